//! Eight `f32` lanes, the unit the wide BVH computes in: one AVX register where the CPU has AVX,
//! else two halves of four (SSE2 on x86-64, `simd128` in the page, NEON on ARM).
//!
//! The box test and the triangle test are written once, over [`Lanes`]. Each lane does the same
//! IEEE operations in the same order whichever type runs it, so both give the same bits; only
//! `min` and `max` are left to each instruction set where a lane is NaN, as they were before
//! the tests were shared (a NaN arises there only for a ray that runs along a slab's plane, which
//! the careful box test maps to ±∞ first).

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;
use std::ops::{Add, Div, Mul, Sub};

use glam::Vec4;

/// Lanes a value holds.
pub(super) const LANES: usize = 8;

/// Eight lanes of `f32` and what the wide BVH's tests do with them. Comparisons return a
/// bitmask, bit `i` for lane `i`; every comparison but [`Lanes::ne`] is false where a lane is NaN.
///
/// A type may need instructions that not every CPU has ([`Octet`]: AVX). So `load` and `splat`,
/// the only ways to make a value, are unsafe: their caller promises that the CPU has them, and
/// every other operation acts on values made so.
pub(super) trait Lanes:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
    /// The eight values stored as two halves of four.
    ///
    /// # Safety
    /// The CPU must have the instructions the type uses.
    unsafe fn load(halves: &[Vec4; 2]) -> Self;

    /// `x` in every lane.
    ///
    /// # Safety
    /// The CPU must have the instructions the type uses.
    unsafe fn splat(x: f32) -> Self;

    fn min(self, other: Self) -> Self;
    fn max(self, other: Self) -> Self;
    /// `value` in the lanes that are NaN.
    fn nan_to(self, value: f32) -> Self;
    fn lt(self, other: Self) -> u32;
    fn le(self, other: Self) -> u32;
    fn gt(self, other: Self) -> u32;
    fn eq(self, other: Self) -> u32;
    /// Lanes that differ, NaN included (as `!=`).
    fn ne(self, other: Self) -> u32;
    fn to_array(self) -> [f32; LANES];
}

/// Two halves of four lanes, in glam's vectors: SSE2 on x86-64, `simd128` in the page.
#[derive(Clone, Copy)]
pub(super) struct Halves([Vec4; 2]);

impl Halves {
    #[inline(always)]
    fn map(self, other: Halves, f: impl Fn(Vec4, Vec4) -> Vec4) -> Halves {
        Halves([f(self.0[0], other.0[0]), f(self.0[1], other.0[1])])
    }

    #[inline(always)]
    fn mask(self, other: Halves, f: impl Fn(Vec4, Vec4) -> glam::BVec4A) -> u32 {
        f(self.0[0], other.0[0]).bitmask() | f(self.0[1], other.0[1]).bitmask() << 4
    }
}

macro_rules! halves_arithmetic {
    ($($trait:ident $method:ident $op:tt),*) => {$(
        impl $trait for Halves {
            type Output = Halves;
            #[inline(always)]
            fn $method(self, other: Halves) -> Halves {
                self.map(other, |a, b| a $op b)
            }
        }
    )*};
}
halves_arithmetic!(Add add +, Sub sub -, Mul mul *, Div div /);

impl Lanes for Halves {
    #[inline(always)]
    unsafe fn load(halves: &[Vec4; 2]) -> Halves {
        Halves(*halves)
    }

    #[inline(always)]
    unsafe fn splat(x: f32) -> Halves {
        Halves([Vec4::splat(x); 2])
    }

    #[inline(always)]
    fn min(self, other: Halves) -> Halves {
        self.map(other, Vec4::min)
    }

    #[inline(always)]
    fn max(self, other: Halves) -> Halves {
        self.map(other, Vec4::max)
    }

    #[inline(always)]
    fn nan_to(self, value: f32) -> Halves {
        Halves(self.0.map(|v| Vec4::select(v.is_nan_mask(), Vec4::splat(value), v)))
    }

    #[inline(always)]
    fn lt(self, other: Halves) -> u32 {
        self.mask(other, Vec4::cmplt)
    }

    #[inline(always)]
    fn le(self, other: Halves) -> u32 {
        self.mask(other, Vec4::cmple)
    }

    #[inline(always)]
    fn gt(self, other: Halves) -> u32 {
        self.mask(other, Vec4::cmpgt)
    }

    #[inline(always)]
    fn eq(self, other: Halves) -> u32 {
        self.mask(other, Vec4::cmpeq)
    }

    #[inline(always)]
    fn ne(self, other: Halves) -> u32 {
        self.mask(other, Vec4::cmpne)
    }

    #[inline(always)]
    fn to_array(self) -> [f32; LANES] {
        bytemuck::cast(self.0)
    }
}

/// The eight lanes in one AVX register. Its operations inline only into code compiled with AVX
/// enabled (`#[target_feature(enable = "avx")]`), where they become one instruction each.
///
/// Its safe operations rely on this: an `Octet` is made only by [`Lanes::load`] and
/// [`Lanes::splat`], whose callers promise AVX. Give it no safe constructor (no `Default`, no
/// `From`, no `Pod`).
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy)]
pub(super) struct Octet(__m256);

#[cfg(target_arch = "x86_64")]
macro_rules! octet_arithmetic {
    ($($trait:ident $method:ident $intrinsic:ident),*) => {$(
        impl $trait for Octet {
            type Output = Octet;
            #[inline(always)]
            fn $method(self, other: Octet) -> Octet {
                // SAFETY: an `Octet` exists only where the CPU has AVX (`Lanes`' contract).
                Octet(unsafe { $intrinsic(self.0, other.0) })
            }
        }
    )*};
}
#[cfg(target_arch = "x86_64")]
octet_arithmetic!(Add add _mm256_add_ps, Sub sub _mm256_sub_ps, Mul mul _mm256_mul_ps, Div div _mm256_div_ps);

#[cfg(target_arch = "x86_64")]
impl Octet {
    /// The lanes where `PREDICATE` (one of `_mm256_cmp_ps`'s) holds, as a bitmask.
    #[inline(always)]
    fn mask<const PREDICATE: i32>(self, other: Octet) -> u32 {
        // SAFETY: as for the arithmetic.
        unsafe { _mm256_movemask_ps(_mm256_cmp_ps::<PREDICATE>(self.0, other.0)) as u32 }
    }
}

#[cfg(target_arch = "x86_64")]
impl Lanes for Octet {
    #[inline(always)]
    unsafe fn load(halves: &[Vec4; 2]) -> Octet {
        // SAFETY: the caller's promise that the CPU has AVX; the read is within `halves`.
        unsafe { Octet(_mm256_loadu_ps(halves.as_ptr().cast())) }
    }

    #[inline(always)]
    unsafe fn splat(x: f32) -> Octet {
        // SAFETY: the caller's promise that the CPU has AVX.
        unsafe { Octet(_mm256_set1_ps(x)) }
    }

    #[inline(always)]
    fn min(self, other: Octet) -> Octet {
        // SAFETY: as for the arithmetic.
        Octet(unsafe { _mm256_min_ps(self.0, other.0) })
    }

    #[inline(always)]
    fn max(self, other: Octet) -> Octet {
        // SAFETY: as for the arithmetic.
        Octet(unsafe { _mm256_max_ps(self.0, other.0) })
    }

    #[inline(always)]
    fn nan_to(self, value: f32) -> Octet {
        // SAFETY: as for the arithmetic.
        unsafe {
            let nan = _mm256_cmp_ps::<_CMP_UNORD_Q>(self.0, self.0);
            Octet(_mm256_blendv_ps(self.0, _mm256_set1_ps(value), nan))
        }
    }

    #[inline(always)]
    fn lt(self, other: Octet) -> u32 {
        self.mask::<_CMP_LT_OQ>(other)
    }

    #[inline(always)]
    fn le(self, other: Octet) -> u32 {
        self.mask::<_CMP_LE_OQ>(other)
    }

    #[inline(always)]
    fn gt(self, other: Octet) -> u32 {
        self.mask::<_CMP_GT_OQ>(other)
    }

    #[inline(always)]
    fn eq(self, other: Octet) -> u32 {
        self.mask::<_CMP_EQ_OQ>(other)
    }

    #[inline(always)]
    fn ne(self, other: Octet) -> u32 {
        self.mask::<_CMP_NEQ_UQ>(other)
    }

    #[inline(always)]
    fn to_array(self) -> [f32; LANES] {
        bytemuck::cast(self.0)
    }
}
