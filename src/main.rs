//! The `mirador` command line: headless screenshots now; the viewer, the ray tracer and
//! `compare` as their issues land.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, bail};
use clap::{CommandFactory, Parser, Subcommand};

use mirador::gpu::texture::GpuTexture;
use mirador::gpu::{Gpu, Stopwatch, readback};
use mirador::raster::{OUTPUT_FORMAT, Renderer};
use mirador::{RenderSettings, Scene, output};

#[derive(Parser)]
#[command(
    name = "mirador",
    version,
    about = "A hybrid renderer for learning the classic realistic-rendering techniques"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene with the z-buffer rasterizer into a PNG.
    Render(RenderArgs),
}

#[derive(clap::Args)]
struct RenderArgs {
    /// Scene file (TOML, or a .gltf/.glb model). Default: the built-in showcase.
    scene: Option<PathBuf>,
    /// Output PNG, written atomically.
    #[arg(short, long)]
    output: PathBuf,
    /// Image width in pixels (default: the scene camera's).
    #[arg(long)]
    width: Option<u32>,
    /// Image height in pixels (default: the scene camera's).
    #[arg(long)]
    height: Option<u32>,
    /// Change a render setting, as a dotted key and a TOML value: `--set terms.specular=false`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Print the time of each step.
    #[arg(long)]
    stats: bool,
}

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    let result = match cli.command {
        Some(Command::Render(args)) => render(args),
        None => {
            // The interactive viewer takes this place once it exists.
            Cli::command().print_help().expect("writing help to stdout");
            Ok(())
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error:#}");
            ExitCode::FAILURE
        }
    }
}

/// The scene named on the command line, or the built-in showcase.
fn load_scene(path: Option<&Path>) -> anyhow::Result<Scene> {
    Ok(match path {
        Some(path) => Scene::load(path)?,
        None => Scene::showcase()?,
    })
}

/// The scene's settings with the command line's `--set` assignments applied, in order.
fn settings(scene: &Scene, assignments: &[String]) -> anyhow::Result<RenderSettings> {
    let mut settings = scene.settings.clone();
    for assignment in assignments {
        settings.set(assignment).context("--set")?;
    }
    Ok(settings)
}

fn render(args: RenderArgs) -> anyhow::Result<()> {
    let extension = args.output.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if extension.as_deref() != Some("png") {
        bail!("{}: the output must be a .png file", args.output.display());
    }
    let mut clock = Stopwatch::default();
    let mut scene = clock.time("scene load", || load_scene(args.scene.as_deref()))?;
    let settings = settings(&scene, &args.set)?;
    scene.settings = settings.clone();
    scene.camera.width = args.width.unwrap_or(scene.camera.width);
    scene.camera.height = args.height.unwrap_or(scene.camera.height);
    scene.camera.validate().context("--width/--height")?;

    let gpu = clock.time("device", Gpu::headless)?;
    let renderer = clock.time("pipelines", || Renderer::new(&gpu.device, OUTPUT_FORMAT));
    let size = (scene.camera.width, scene.camera.height);
    let (scene_gpu, targets, output) = clock.time("upload", || {
        let scene_gpu = renderer.upload(&gpu, &scene);
        let targets = renderer.targets(&gpu.device, size);
        let output = GpuTexture::target(&gpu.device, "cli::output", size, OUTPUT_FORMAT);
        gpu.wait();
        (scene_gpu, targets, output)
    });
    // The first frame also pays for the driver's lazy pipeline compilation; the second is what
    // an interactive frame costs. `--stats` reports both.
    for lap in ["first frame", "frame"] {
        clock.time(lap, || {
            renderer.render(&gpu, &scene, &scene_gpu, &settings, &targets, &output.view);
            gpu.wait();
        });
        if !args.stats {
            break;
        }
    }
    let pixels = clock.time("readback", || readback::read_rgba8(&gpu.device, &gpu.queue, &output.texture));
    let image = image::RgbaImage::from_raw(size.0, size.1, pixels).expect("readback returns one RGBA8 texel per pixel");
    clock
        .time("encode + write", || output::write_png_atomically(&image, &args.output))
        .with_context(|| format!("{}: cannot write the image", args.output.display()))?;
    if args.stats {
        println!("adapter: {}", gpu.describe());
        let triangles: usize = scene.objects.iter().map(|o| scene.tessellate(o).triangle_count()).sum();
        println!(
            "scene: {} objects, {} triangles, {} lights, {}×{} pixels",
            scene.objects.len(),
            triangles,
            scene.lights.len(),
            size.0,
            size.1
        );
        println!("{}", clock.report());
    }
    Ok(())
}
