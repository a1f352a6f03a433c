//! The Utah teapot as a Wavefront OBJ with its MTL: the file `tests/data/obj/teapot.obj` the
//! OBJ tests and renders use, made here from Martin Newell's 1975 data (public domain).
//!
//! The teapot is 32 bicubic Bézier patches over 290 control points: the rim (4 patches), the body
//! (8), the handle (4), the spout (4), the lid (8) and the bottom (4). Each patch is
//! `P(u, v) = Σᵢ Σⱼ Bᵢ(u)·Bⱼ(v)·Pᵢⱼ` with the Bernstein polynomials
//! `B₀ = (1−t)³, B₁ = 3t(1−t)², B₂ = 3t²(1−t), B₃ = t³`, and its outward normal is
//! `∂P/∂v × ∂P/∂u` (Newell's rows run down the teapot, his columns around it), both evaluated
//! exactly here on an `N × N` grid of quads per patch. Where a patch edge collapses
//! to a point (the top of the knob, the centre of the bottom) the normal is taken a hair inside
//! the patch. Positions shared by neighbouring patches are written once, so the mesh is closed
//! where Newell's patches meet; normals and texture coordinates are per patch. Quads that
//! collapse to triangles at those points are written as triangles.
//!
//! Newell's coordinates have z up and the teapot standing on z = 0; they are turned to Mirador's
//! y up, `(x, y, z) → (x, z, −y)`, keeping his units (the teapot is 3.15 tall and the body 4
//! across). The lid is left as Newell drew it, a little narrower than the rim.
//!
//! Run with `cargo run --example teapot_obj [DIR] [N]`; writes `teapot.obj` and `teapot.mtl`
//! into DIR (default `tests/data/obj`) with N × N quads per patch (default 8).

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::Context;
use glam::{Vec2, Vec3};

/// Which patches make which group, and the material each is drawn in.
const GROUPS: [(&str, std::ops::Range<usize>, &str); 5] = [
    ("body", 0..12, "porcelain"),
    ("handle", 12..16, "porcelain"),
    ("spout", 16..20, "porcelain"),
    ("lid", 20..28, "glaze"),
    ("bottom", 28..32, "porcelain"),
];

const MTL: &str = "\
# The Utah teapot's materials: written by examples/teapot_obj.rs.

newmtl porcelain
Ka 0.1 0.1 0.1
Kd 0.8 0.76 0.7
Ks 0.35 0.35 0.35
Ns 80
illum 2

newmtl glaze
Ka 0.1 0.1 0.1
Kd 0.12 0.25 0.55
Ks 0.5 0.5 0.5
Ns 160
illum 2
";

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let dir = args.next().map_or_else(|| PathBuf::from("tests/data/obj"), PathBuf::from);
    let n: usize = match args.next() {
        Some(n) => n.parse().context("N, the quads per patch side, must be a whole number")?,
        None => 8,
    };
    anyhow::ensure!((1..=64).contains(&n), "N must be between 1 and 64");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let obj = teapot_obj(n);
    std::fs::write(dir.join("teapot.obj"), obj).context("writing teapot.obj")?;
    std::fs::write(dir.join("teapot.mtl"), MTL).context("writing teapot.mtl")?;
    println!("wrote {0}/teapot.obj and {0}/teapot.mtl ({n} × {n} quads per patch)", dir.display());
    Ok(())
}

fn teapot_obj(n: usize) -> String {
    let mut out = String::new();
    out.push_str("# The Utah teapot (Martin Newell, 1975; public domain): 32 bicubic Bezier patches,\n");
    let _ = writeln!(out, "# tessellated into {n} x {n} quads each by examples/teapot_obj.rs. y is up.");
    out.push_str("mtllib teapot.mtl\n");
    let mut positions: Vec<Vec3> = Vec::new();
    let mut position_index: HashMap<[i64; 3], usize> = HashMap::new();
    let mut normal_count = 0;
    let mut faces = String::new();
    let mut attributes = String::new();
    for (group, patches, material) in GROUPS {
        let _ = writeln!(faces, "g {group}\nusemtl {material}");
        for patch in patches {
            let points: [Vec3; 16] = std::array::from_fn(|k| {
                let [x, y, z] = VERTICES[PATCHES[patch][k]];
                Vec3::new(x, z, -y)
            });
            // (position, normal, uv) indices of the grid, 1-based as OBJ counts.
            let mut grid = vec![[0usize; 3]; (n + 1) * (n + 1)];
            for i in 0..=n {
                for j in 0..=n {
                    let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
                    let p = evaluate(&points, u, v);
                    let key = p.to_array().map(|c| (c * 1e5).round() as i64);
                    let position = *position_index.entry(key).or_insert_with(|| {
                        positions.push(p);
                        positions.len()
                    });
                    let normal = normal(&points, u, v);
                    let _ = writeln!(attributes, "vn {} {} {}", normal.x, normal.y, normal.z);
                    let _ = writeln!(attributes, "vt {} {}", v, u);
                    normal_count += 1;
                    grid[i * (n + 1) + j] = [position, normal_count, normal_count];
                }
            }
            for i in 0..n {
                for j in 0..n {
                    let corners = [(i, j), (i, j + 1), (i + 1, j + 1), (i + 1, j)].map(|(a, b)| grid[a * (n + 1) + b]);
                    // Counter-clockwise around the outward ∂P/∂v × ∂P/∂u; corners that coincide
                    // are dropped.
                    let mut distinct: Vec<[usize; 3]> = Vec::with_capacity(4);
                    for c in corners {
                        if distinct.iter().all(|d| d[0] != c[0]) {
                            distinct.push(c);
                        }
                    }
                    if distinct.len() < 3 {
                        continue;
                    }
                    faces.push('f');
                    for [p, n, t] in distinct {
                        let _ = write!(faces, " {p}/{t}/{n}");
                    }
                    faces.push('\n');
                }
            }
        }
    }
    for p in &positions {
        let _ = writeln!(out, "v {} {} {}", p.x, p.y, p.z);
    }
    out.push_str(&attributes);
    out.push_str(&faces);
    out
}

/// The Bernstein polynomials of degree 3 at `t`, and their derivatives.
fn bernstein(t: f32) -> ([f32; 4], [f32; 4]) {
    let s = 1.0 - t;
    let value = [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t];
    let derivative = [-3.0 * s * s, 3.0 * s * s - 6.0 * t * s, 6.0 * t * s - 3.0 * t * t, 3.0 * t * t];
    (value, derivative)
}

/// `P(u, v)`, and `∂P/∂u`, `∂P/∂v`; rows of `points` go with `u`, columns with `v`.
fn surface(points: &[Vec3; 16], u: f32, v: f32) -> (Vec3, Vec3, Vec3) {
    let ((bu, du), (bv, dv)) = (bernstein(u), bernstein(v));
    let (mut p, mut pu, mut pv) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
    for i in 0..4 {
        for j in 0..4 {
            let c = points[i * 4 + j];
            p += bu[i] * bv[j] * c;
            pu += du[i] * bv[j] * c;
            pv += bu[i] * dv[j] * c;
        }
    }
    (p, pu, pv)
}

fn evaluate(points: &[Vec3; 16], u: f32, v: f32) -> Vec3 {
    surface(points, u, v).0
}

/// The unit outward normal `∂P/∂v × ∂P/∂u`, or where a patch edge collapses to a point (the cross
/// product vanishes), the normal a hair inside the patch.
fn normal(points: &[Vec3; 16], u: f32, v: f32) -> Vec3 {
    let (_, pu, pv) = surface(points, u, v);
    let n = pv.cross(pu);
    if n.length() > 1e-6 {
        return n.normalize();
    }
    let inside = Vec2::new(u, v).clamp(Vec2::splat(1e-3), Vec2::splat(1.0 - 1e-3));
    let (_, pu, pv) = surface(points, inside.x, inside.y);
    pv.cross(pu).normalize()
}

/// Newell's patches: 16 control point indices each, row by row.
#[rustfmt::skip]
const PATCHES: [[usize; 16]; 32] = [
    // Rim.
    [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15],
    [3, 16, 17, 18, 7, 19, 20, 21, 11, 22, 23, 24, 15, 25, 26, 27],
    [18, 28, 29, 30, 21, 31, 32, 33, 24, 34, 35, 36, 27, 37, 38, 39],
    [30, 40, 41, 0, 33, 42, 43, 4, 36, 44, 45, 8, 39, 46, 47, 12],
    // Body.
    [12, 13, 14, 15, 48, 49, 50, 51, 52, 53, 54, 55, 56, 57, 58, 59],
    [15, 25, 26, 27, 51, 60, 61, 62, 55, 63, 64, 65, 59, 66, 67, 68],
    [27, 37, 38, 39, 62, 69, 70, 71, 65, 72, 73, 74, 68, 75, 76, 77],
    [39, 46, 47, 12, 71, 78, 79, 48, 74, 80, 81, 52, 77, 82, 83, 56],
    [56, 57, 58, 59, 84, 85, 86, 87, 88, 89, 90, 91, 92, 93, 94, 95],
    [59, 66, 67, 68, 87, 96, 97, 98, 91, 99, 100, 101, 95, 102, 103, 104],
    [68, 75, 76, 77, 98, 105, 106, 107, 101, 108, 109, 110, 104, 111, 112, 113],
    [77, 82, 83, 56, 107, 114, 115, 84, 110, 116, 117, 88, 113, 118, 119, 92],
    // Handle.
    [120, 121, 122, 123, 124, 125, 126, 127, 128, 129, 130, 131, 132, 133, 134, 135],
    [123, 136, 137, 120, 127, 138, 139, 124, 131, 140, 141, 128, 135, 142, 143, 132],
    [132, 133, 134, 135, 144, 145, 146, 147, 148, 149, 150, 151, 68, 152, 153, 154],
    [135, 142, 143, 132, 147, 155, 156, 144, 151, 157, 158, 148, 154, 159, 160, 68],
    // Spout.
    [161, 162, 163, 164, 165, 166, 167, 168, 169, 170, 171, 172, 173, 174, 175, 176],
    [164, 177, 178, 161, 168, 179, 180, 165, 172, 181, 182, 169, 176, 183, 184, 173],
    [173, 174, 175, 176, 185, 186, 187, 188, 189, 190, 191, 192, 193, 194, 195, 196],
    [176, 183, 184, 173, 188, 197, 198, 185, 192, 199, 200, 189, 196, 201, 202, 193],
    // Lid.
    [203, 203, 203, 203, 204, 205, 206, 207, 208, 208, 208, 208, 209, 210, 211, 212],
    [203, 203, 203, 203, 207, 213, 214, 215, 208, 208, 208, 208, 212, 216, 217, 218],
    [203, 203, 203, 203, 215, 219, 220, 221, 208, 208, 208, 208, 218, 222, 223, 224],
    [203, 203, 203, 203, 221, 225, 226, 204, 208, 208, 208, 208, 224, 227, 228, 209],
    [209, 210, 211, 212, 229, 230, 231, 232, 233, 234, 235, 236, 237, 238, 239, 240],
    [212, 216, 217, 218, 232, 241, 242, 243, 236, 244, 245, 246, 240, 247, 248, 249],
    [218, 222, 223, 224, 243, 250, 251, 252, 246, 253, 254, 255, 249, 256, 257, 258],
    [224, 227, 228, 209, 252, 259, 260, 229, 255, 261, 262, 233, 258, 263, 264, 237],
    // Bottom.
    [265, 265, 265, 265, 266, 267, 268, 269, 270, 271, 272, 273, 92, 119, 118, 113],
    [265, 265, 265, 265, 269, 274, 275, 276, 273, 277, 278, 279, 113, 112, 111, 104],
    [265, 265, 265, 265, 276, 280, 281, 282, 279, 283, 284, 285, 104, 103, 102, 95],
    [265, 265, 265, 265, 282, 286, 287, 266, 285, 288, 289, 270, 95, 94, 93, 92],
];

/// Newell's control points, z up.
#[rustfmt::skip]
const VERTICES: [[f32; 3]; 290] = [
    [1.4, 0.0, 2.4], [1.4, -0.784, 2.4], [0.784, -1.4, 2.4], [0.0, -1.4, 2.4],
    [1.3375, 0.0, 2.53125], [1.3375, -0.749, 2.53125], [0.749, -1.3375, 2.53125], [0.0, -1.3375, 2.53125],
    [1.4375, 0.0, 2.53125], [1.4375, -0.805, 2.53125], [0.805, -1.4375, 2.53125], [0.0, -1.4375, 2.53125],
    [1.5, 0.0, 2.4], [1.5, -0.84, 2.4], [0.84, -1.5, 2.4], [0.0, -1.5, 2.4],
    [-0.784, -1.4, 2.4], [-1.4, -0.784, 2.4], [-1.4, 0.0, 2.4], [-0.749, -1.3375, 2.53125],
    [-1.3375, -0.749, 2.53125], [-1.3375, 0.0, 2.53125], [-0.805, -1.4375, 2.53125], [-1.4375, -0.805, 2.53125],
    [-1.4375, 0.0, 2.53125], [-0.84, -1.5, 2.4], [-1.5, -0.84, 2.4], [-1.5, 0.0, 2.4],
    [-1.4, 0.784, 2.4], [-0.784, 1.4, 2.4], [0.0, 1.4, 2.4], [-1.3375, 0.749, 2.53125],
    [-0.749, 1.3375, 2.53125], [0.0, 1.3375, 2.53125], [-1.4375, 0.805, 2.53125], [-0.805, 1.4375, 2.53125],
    [0.0, 1.4375, 2.53125], [-1.5, 0.84, 2.4], [-0.84, 1.5, 2.4], [0.0, 1.5, 2.4],
    [0.784, 1.4, 2.4], [1.4, 0.784, 2.4], [0.749, 1.3375, 2.53125], [1.3375, 0.749, 2.53125],
    [0.805, 1.4375, 2.53125], [1.4375, 0.805, 2.53125], [0.84, 1.5, 2.4], [1.5, 0.84, 2.4],
    [1.75, 0.0, 1.875], [1.75, -0.98, 1.875], [0.98, -1.75, 1.875], [0.0, -1.75, 1.875],
    [2.0, 0.0, 1.35], [2.0, -1.12, 1.35], [1.12, -2.0, 1.35], [0.0, -2.0, 1.35],
    [2.0, 0.0, 0.9], [2.0, -1.12, 0.9], [1.12, -2.0, 0.9], [0.0, -2.0, 0.9],
    [-0.98, -1.75, 1.875], [-1.75, -0.98, 1.875], [-1.75, 0.0, 1.875], [-1.12, -2.0, 1.35],
    [-2.0, -1.12, 1.35], [-2.0, 0.0, 1.35], [-1.12, -2.0, 0.9], [-2.0, -1.12, 0.9],
    [-2.0, 0.0, 0.9], [-1.75, 0.98, 1.875], [-0.98, 1.75, 1.875], [0.0, 1.75, 1.875],
    [-2.0, 1.12, 1.35], [-1.12, 2.0, 1.35], [0.0, 2.0, 1.35], [-2.0, 1.12, 0.9],
    [-1.12, 2.0, 0.9], [0.0, 2.0, 0.9], [0.98, 1.75, 1.875], [1.75, 0.98, 1.875],
    [1.12, 2.0, 1.35], [2.0, 1.12, 1.35], [1.12, 2.0, 0.9], [2.0, 1.12, 0.9],
    [2.0, 0.0, 0.45], [2.0, -1.12, 0.45], [1.12, -2.0, 0.45], [0.0, -2.0, 0.45],
    [1.5, 0.0, 0.225], [1.5, -0.84, 0.225], [0.84, -1.5, 0.225], [0.0, -1.5, 0.225],
    [1.5, 0.0, 0.15], [1.5, -0.84, 0.15], [0.84, -1.5, 0.15], [0.0, -1.5, 0.15],
    [-1.12, -2.0, 0.45], [-2.0, -1.12, 0.45], [-2.0, 0.0, 0.45], [-0.84, -1.5, 0.225],
    [-1.5, -0.84, 0.225], [-1.5, 0.0, 0.225], [-0.84, -1.5, 0.15], [-1.5, -0.84, 0.15],
    [-1.5, 0.0, 0.15], [-2.0, 1.12, 0.45], [-1.12, 2.0, 0.45], [0.0, 2.0, 0.45],
    [-1.5, 0.84, 0.225], [-0.84, 1.5, 0.225], [0.0, 1.5, 0.225], [-1.5, 0.84, 0.15],
    [-0.84, 1.5, 0.15], [0.0, 1.5, 0.15], [1.12, 2.0, 0.45], [2.0, 1.12, 0.45],
    [0.84, 1.5, 0.225], [1.5, 0.84, 0.225], [0.84, 1.5, 0.15], [1.5, 0.84, 0.15],
    [-1.6, 0.0, 2.025], [-1.6, -0.3, 2.025], [-1.5, -0.3, 2.25], [-1.5, 0.0, 2.25],
    [-2.3, 0.0, 2.025], [-2.3, -0.3, 2.025], [-2.5, -0.3, 2.25], [-2.5, 0.0, 2.25],
    [-2.7, 0.0, 2.025], [-2.7, -0.3, 2.025], [-3.0, -0.3, 2.25], [-3.0, 0.0, 2.25],
    [-2.7, 0.0, 1.8], [-2.7, -0.3, 1.8], [-3.0, -0.3, 1.8], [-3.0, 0.0, 1.8],
    [-1.5, 0.3, 2.25], [-1.6, 0.3, 2.025], [-2.5, 0.3, 2.25], [-2.3, 0.3, 2.025],
    [-3.0, 0.3, 2.25], [-2.7, 0.3, 2.025], [-3.0, 0.3, 1.8], [-2.7, 0.3, 1.8],
    [-2.7, 0.0, 1.575], [-2.7, -0.3, 1.575], [-3.0, -0.3, 1.35], [-3.0, 0.0, 1.35],
    [-2.5, 0.0, 1.125], [-2.5, -0.3, 1.125], [-2.65, -0.3, 0.9375], [-2.65, 0.0, 0.9375],
    [-2.0, -0.3, 0.9], [-1.9, -0.3, 0.6], [-1.9, 0.0, 0.6], [-3.0, 0.3, 1.35],
    [-2.7, 0.3, 1.575], [-2.65, 0.3, 0.9375], [-2.5, 0.3, 1.125], [-1.9, 0.3, 0.6],
    [-2.0, 0.3, 0.9], [1.7, 0.0, 1.425], [1.7, -0.66, 1.425], [1.7, -0.66, 0.6],
    [1.7, 0.0, 0.6], [2.6, 0.0, 1.425], [2.6, -0.66, 1.425], [3.1, -0.66, 0.825],
    [3.1, 0.0, 0.825], [2.3, 0.0, 2.1], [2.3, -0.25, 2.1], [2.4, -0.25, 2.025],
    [2.4, 0.0, 2.025], [2.7, 0.0, 2.4], [2.7, -0.25, 2.4], [3.3, -0.25, 2.4],
    [3.3, 0.0, 2.4], [1.7, 0.66, 0.6], [1.7, 0.66, 1.425], [3.1, 0.66, 0.825],
    [2.6, 0.66, 1.425], [2.4, 0.25, 2.025], [2.3, 0.25, 2.1], [3.3, 0.25, 2.4],
    [2.7, 0.25, 2.4], [2.8, 0.0, 2.475], [2.8, -0.25, 2.475], [3.525, -0.25, 2.49375],
    [3.525, 0.0, 2.49375], [2.9, 0.0, 2.475], [2.9, -0.15, 2.475], [3.45, -0.15, 2.5125],
    [3.45, 0.0, 2.5125], [2.8, 0.0, 2.4], [2.8, -0.15, 2.4], [3.2, -0.15, 2.4],
    [3.2, 0.0, 2.4], [3.525, 0.25, 2.49375], [2.8, 0.25, 2.475], [3.45, 0.15, 2.5125],
    [2.9, 0.15, 2.475], [3.2, 0.15, 2.4], [2.8, 0.15, 2.4], [0.0, 0.0, 3.15],
    [0.8, 0.0, 3.15], [0.8, -0.45, 3.15], [0.45, -0.8, 3.15], [0.0, -0.8, 3.15],
    [0.0, 0.0, 2.85], [0.2, 0.0, 2.7], [0.2, -0.112, 2.7], [0.112, -0.2, 2.7],
    [0.0, -0.2, 2.7], [-0.45, -0.8, 3.15], [-0.8, -0.45, 3.15], [-0.8, 0.0, 3.15],
    [-0.112, -0.2, 2.7], [-0.2, -0.112, 2.7], [-0.2, 0.0, 2.7], [-0.8, 0.45, 3.15],
    [-0.45, 0.8, 3.15], [0.0, 0.8, 3.15], [-0.2, 0.112, 2.7], [-0.112, 0.2, 2.7],
    [0.0, 0.2, 2.7], [0.45, 0.8, 3.15], [0.8, 0.45, 3.15], [0.112, 0.2, 2.7],
    [0.2, 0.112, 2.7], [0.4, 0.0, 2.55], [0.4, -0.224, 2.55], [0.224, -0.4, 2.55],
    [0.0, -0.4, 2.55], [1.3, 0.0, 2.55], [1.3, -0.728, 2.55], [0.728, -1.3, 2.55],
    [0.0, -1.3, 2.55], [1.3, 0.0, 2.4], [1.3, -0.728, 2.4], [0.728, -1.3, 2.4],
    [0.0, -1.3, 2.4], [-0.224, -0.4, 2.55], [-0.4, -0.224, 2.55], [-0.4, 0.0, 2.55],
    [-0.728, -1.3, 2.55], [-1.3, -0.728, 2.55], [-1.3, 0.0, 2.55], [-0.728, -1.3, 2.4],
    [-1.3, -0.728, 2.4], [-1.3, 0.0, 2.4], [-0.4, 0.224, 2.55], [-0.224, 0.4, 2.55],
    [0.0, 0.4, 2.55], [-1.3, 0.728, 2.55], [-0.728, 1.3, 2.55], [0.0, 1.3, 2.55],
    [-1.3, 0.728, 2.4], [-0.728, 1.3, 2.4], [0.0, 1.3, 2.4], [0.224, 0.4, 2.55],
    [0.4, 0.224, 2.55], [0.728, 1.3, 2.55], [1.3, 0.728, 2.55], [0.728, 1.3, 2.4],
    [1.3, 0.728, 2.4], [0.0, 0.0, 0.0], [1.425, 0.0, 0.0], [1.425, 0.798, 0.0],
    [0.798, 1.425, 0.0], [0.0, 1.425, 0.0], [1.5, 0.0, 0.075], [1.5, 0.84, 0.075],
    [0.84, 1.5, 0.075], [0.0, 1.5, 0.075], [-0.798, 1.425, 0.0], [-1.425, 0.798, 0.0],
    [-1.425, 0.0, 0.0], [-0.84, 1.5, 0.075], [-1.5, 0.84, 0.075], [-1.5, 0.0, 0.075],
    [-1.425, -0.798, 0.0], [-0.798, -1.425, 0.0], [0.0, -1.425, 0.0], [-1.5, -0.84, 0.075],
    [-0.84, -1.5, 0.075], [0.0, -1.5, 0.075], [0.798, -1.425, 0.0], [1.425, -0.798, 0.0],
    [0.84, -1.5, 0.075], [1.5, -0.84, 0.075],
];
