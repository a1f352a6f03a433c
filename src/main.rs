//! The `mirador` command line: the interactive viewer (`view`, and the bare `mirador`), headless
//! screenshots from the rasterizer (`render`) and the ray tracer (`trace`), and the two side by
//! side (`compare`).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, bail};
use clap::{Parser, Subcommand};

use mirador::compare::sheet::{Panel, flip_legend, sheet, with_footer};
use mirador::course::{Linked, PageLink};
use mirador::gpu::texture::GpuTexture;
use mirador::gpu::{Gpu, Stopwatch, readback};
use mirador::linear_output::LinearImage;
use mirador::raster::{FrameReport, FrameTargets, OUTPUT_FORMAT, Renderer, drawn_size};
use mirador::scene::file::overrides;
use mirador::settings::AntiAliasing;
use mirador::trace::accel::AccelKind;
use mirador::trace::{RadianceImage, RenderControl, Tracer};
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
    /// Open the interactive viewer (what `mirador` alone does): raster, ray traced, split and
    /// difference views, every technique's settings in a panel. Press F1 in the window for keys.
    View(ViewArgs),
    /// Render a scene with the z-buffer rasterizer into a PNG.
    Render {
        #[command(flatten)]
        scene: SceneArgs,
        /// Output PNG, written atomically.
        #[arg(short, long)]
        output: PathBuf,
        /// Also write the linear radiance, before exposure, clamp and sRGB encoding, as an
        /// OpenEXR file (32-bit float RGB; the rasterizer's half-float HDR target), atomically.
        #[arg(long, value_name = "FILE.exr")]
        exr: Option<PathBuf>,
    },
    /// Render a scene with the Whitted ray tracer into a PNG.
    Trace {
        #[command(flatten)]
        scene: SceneArgs,
        #[command(flatten)]
        trace: TraceArgs,
        /// Output PNG, written atomically.
        #[arg(short, long)]
        output: PathBuf,
        /// Also write the linear radiance the tracer computed, before exposure, clamp and sRGB
        /// encoding, as an OpenEXR file (32-bit float RGB), atomically.
        #[arg(long, value_name = "FILE.exr")]
        exr: Option<PathBuf>,
    },
    /// Render a scene with both renderers and write a sheet: raster | ray traced | FLIP error.
    Compare {
        #[command(flatten)]
        scene: SceneArgs,
        #[command(flatten)]
        trace: TraceArgs,
        /// The sheet, written atomically.
        #[arg(short, long)]
        output: PathBuf,
        /// Also write the raster image here.
        #[arg(long)]
        raster_out: Option<PathBuf>,
        /// Also write the ray-traced image here.
        #[arg(long)]
        trace_out: Option<PathBuf>,
        /// Also write the FLIP error map here.
        #[arg(long)]
        error_out: Option<PathBuf>,
        /// Also write both renderers' linear radiance (before exposure, clamp and sRGB encoding)
        /// side by side, raster on the left, as one OpenEXR file (32-bit float RGB), atomically.
        #[arg(long, value_name = "FILE.exr")]
        exr: Option<PathBuf>,
        /// Also write the figures as JSON to this file (`-`: standard output, instead of the
        /// text): mean FLIP, the worst 32×32 region, PSNR, as `mirador diff --json` gives them.
        #[arg(long, value_name = "FILE.json")]
        json: Option<PathBuf>,
    },
    /// Explain one pixel: what each renderer computed there, term by term (the rasterizer's
    /// values read back from the GPU, the tracer's ray tree), and why they differ.
    Explain {
        #[command(flatten)]
        scene: SceneArgs,
        #[command(flatten)]
        trace: TraceArgs,
        /// The pixel, `X,Y` from the image's top-left corner.
        #[arg(long, value_name = "X,Y", value_parser = parse_pixel)]
        pixel: [u32; 2],
        /// Write the explanation as JSON to this file (`-`: standard output, instead of the text).
        #[arg(long, value_name = "FILE.json")]
        json: Option<PathBuf>,
    },
    /// The error budget: how much of the raster-vs-traced difference each of the rasterizer's
    /// approximations costs, each swapped for its traced counterpart inside the raster frame
    /// (docs/course/12-error-budget.md).
    Budget {
        #[command(flatten)]
        scene: SceneArgs,
        #[command(flatten)]
        trace: TraceArgs,
        /// Also write the sheet here: the images, a bar per approximation and its error map.
        #[arg(long, value_name = "FILE.png")]
        sheet: Option<PathBuf>,
        /// Write the budget as JSON to this file (`-`: standard output, instead of the text):
        /// `whole`, `floor`, `floor_causes`, and each approximation's `name`, `alone` and
        /// `left_alone`.
        #[arg(long, value_name = "FILE.json")]
        json: Option<PathBuf>,
    },
    /// Labs: write a technique's functions in WGSL and have them checked against Mirador's own and
    /// the ray tracer (docs/course/labs.md).
    Lab {
        #[command(subcommand)]
        command: LabCommand,
    },
    /// Compare two images of the same size: mean FLIP, the worst 32×32 region, and the mean
    /// under a mask.
    Diff {
        /// The correct image (PNG).
        reference: PathBuf,
        /// The image to judge (PNG).
        test: PathBuf,
        /// Only the pixels where this image (of the same size) is not black count in the masked mean.
        #[arg(long, value_name = "MASK.png")]
        mask: Option<PathBuf>,
        /// Write the figures as JSON to this file (`-`: standard output, instead of the text).
        #[arg(long, value_name = "FILE.json")]
        json: Option<PathBuf>,
    },
    /// Print the address of Mirador's page that shows what a command shows: its scene, its
    /// settings and its view. `mirador link render assets/scenes/course/mirror-pair.toml -o
    /// pair.png --set mirrors.depth=2` prints
    /// `?scene=course/mirror-pair.toml&set=mirrors.depth%3D2&view=raster`;
    /// the course's site (web/site.sh) puts one under every command of its chapters.
    Link {
        /// What to print before the query: the page's address (`https://…/mirador/`).
        #[arg(long, value_name = "URL", default_value = "")]
        page: String,
        /// The command, as after `mirador`.
        #[arg(required = true, trailing_var_arg = true, allow_hyphen_values = true)]
        command: Vec<String>,
    },
    /// The course site's mdBook preprocessor (web/site.sh runs mdBook, which runs this).
    #[command(hide = true)]
    Book {
        /// `supports RENDERER`, as mdBook asks first.
        args: Vec<String>,
    },
    /// Copy a scene and every file it reads (textures, maps, models, volumes) into a folder of
    /// your own, the copy naming them there: do an exercise on the copy, the course stays as it
    /// was. Nothing in the folder is overwritten.
    Copy {
        /// The scene file, or a built-in one by its name under assets/scenes
        /// (`course/shadows-methods.toml`).
        scene: PathBuf,
        /// The folder to copy into (made if missing).
        dir: PathBuf,
    },
}

#[derive(Subcommand)]
enum LabCommand {
    /// The labs, one a line: its name, its chapter and its title.
    List,
    /// Write a lab's folder: the student's file (signatures, course comments, neutral bodies),
    /// the task and the public test scenes.
    New {
        /// The lab's name (`mirador lab list`).
        lab: String,
        /// The folder to make.
        dir: PathBuf,
        /// Write the answer key and the teacher's notes instead of the student's stub.
        #[arg(long)]
        solution: bool,
    },
    /// Check a lab's folder: the student's WGSL validated, then its known-answer and image tests
    /// run and scored; writes results.json (Gradescope's format) and report.md there. Exits 0
    /// when every test passed, 1 otherwise.
    Check {
        dir: PathBuf,
        /// The lab to grade, as the teacher names it. The folder's own lab.toml (the student's to
        /// edit) is then not read: neither which lab it is nor its points.
        #[arg(long, value_name = "NAME")]
        lab: Option<String>,
        /// A folder of hidden tests (`*.toml`, the lab's own format) run after the lab's own.
        #[arg(long, value_name = "DIR")]
        tests: Option<PathBuf>,
        /// A points file (`"test name" = points`) in place of the folder's own `[points]`.
        #[arg(long, value_name = "FILE.toml")]
        points: Option<PathBuf>,
        /// The most seconds one test may take; a test that takes longer fails, and the tests
        /// after it are not run.
        #[arg(long, value_name = "SECONDS", default_value_t = 30.0)]
        time_limit: f64,
        /// Also write the results to this file, in --format's form: written even when the
        /// submission cannot be checked at all (a score of 0 that says why).
        #[arg(long, value_name = "FILE.json")]
        results: Option<PathBuf>,
        /// The form of --results: a grading service's.
        #[arg(long, value_enum, default_value_t = mirador::lab::report::Format::Gradescope, requires = "results")]
        format: mirador::lab::report::Format,
    },
    /// Write what a grading service needs to grade a lab (setup and run scripts, the lab's
    /// points and hidden tests): Gradescope's autograder, PrairieLearn's external grader, or a
    /// GitHub Classroom workflow (docs/course/labs.md, "Grading a class").
    Autograder {
        /// The lab's name (`mirador lab list`).
        lab: String,
        /// The folder to write.
        dir: PathBuf,
        /// The service.
        #[arg(long = "for", value_enum)]
        service: mirador::lab::autograder::Service,
        /// A folder of hidden tests (`*.toml`, the lab's own format).
        #[arg(long, value_name = "DIR")]
        tests: Option<PathBuf>,
        /// A points file (`"test name" = points`) over the lab's own.
        #[arg(long, value_name = "FILE.toml")]
        points: Option<PathBuf>,
        /// The Mirador binary to put in the folder (default: this one).
        #[arg(long, value_name = "FILE")]
        binary: Option<PathBuf>,
        /// The most seconds one test may take.
        #[arg(long, value_name = "SECONDS", default_value_t = 60.0)]
        time_limit: f64,
    },
    /// A class's results at a glance: reads every results.json under the paths given (files or
    /// folders) and writes summary.html and summary.md: the score histogram, each test's pass
    /// rate and discrimination, the known mistakes matched most, the submissions that did not
    /// compile, the slowest checks.
    Summary {
        #[arg(required = true)]
        results: Vec<PathBuf>,
        /// The folder to write the page into.
        #[arg(short, long, value_name = "DIR")]
        out: PathBuf,
    },
    /// Exits 0 when test N (from 0, in the order of its `tests`) of a results.json passed: one
    /// test as a GitHub Classroom step.
    Passed { results: PathBuf, index: usize },
    /// Runs a lab's tests from one on, a JSON line each (what `check` runs under its time limit).
    #[command(hide = true)]
    Run {
        dir: PathBuf,
        #[arg(long)]
        from: usize,
        #[arg(long)]
        tests: Option<PathBuf>,
        #[arg(long)]
        lab: Option<String>,
        /// The student's file, where it is not the lab's file in DIR.
        #[arg(long)]
        file: Option<PathBuf>,
        /// Run the answer key instead of the folder's file (a teacher's hidden tests are checked
        /// with it first).
        #[arg(long)]
        key: bool,
    },
}

#[derive(clap::Args, Clone)]
struct SceneArgs {
    /// Scene file (TOML, or a .gltf/.glb/.obj/.ply model). Default: the built-in showcase.
    scene: Option<PathBuf>,
    /// Image width in pixels (default: the scene camera's).
    #[arg(long)]
    width: Option<u32>,
    /// Image height in pixels (default: the scene camera's).
    #[arg(long)]
    height: Option<u32>,
    /// Change a render setting, as a dotted key and a TOML value: `--set terms.specular=false`; or
    /// a value of the scene file: `camera.fovy=30`, `lights.0.intensity=0.5`, `materials.NAME.ks=0.8`,
    /// `objects.NAME.center=[0, 1, 0]` (lights and objects by index or name), `world.ambient=[…]`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Print the time of each step and what was traced.
    #[arg(long)]
    stats: bool,
}

#[derive(clap::Args, Default)]
struct ViewArgs {
    /// Scene file (TOML, or a .gltf/.glb/.obj/.ply model). Default: the built-in showcase.
    scene: Option<PathBuf>,
    /// Change a render setting or a value of the scene file, as a dotted key and a TOML value:
    /// `--set shadows.enabled=false`, `--set camera.fovy=30`, `--set lights.0.intensity=0.5`,
    /// `--set materials.NAME.ks=0.8` (kept when the file is reloaded). The script's `set` step
    /// takes the same.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Run this many frames (after the scripted steps), then exit. Scripted runs neither read
    /// nor write the remembered settings.
    #[arg(long, value_name = "N")]
    frames: Option<u64>,
    /// With --frames: write the window's image after the last frame (PNG, atomically).
    #[arg(long, value_name = "FILE", requires = "frames")]
    screenshot: Option<PathBuf>,
    /// A scripted step, one per frame, in order: `set KEY=VALUE`, `view raster|traced|split|difference`,
    /// `split X`, `orbit DX DY`, `pan DX DY`, `zoom N`, `frame`, `reset`, `reset settings`, `navigate orbit|fly`,
    /// `walk X Y Z`, `pick X Y`, `cursor X Y`, `inspect X Y` (both renderers at that pixel, as the
    /// I key and a click), `probe`, `material KEY=VALUE`, `load FILE`, `scale S`,
    /// `fps N|off`, `help on|off`, `panel on|off`, `overlay on|off`, `wait N`, `wait 2s`,
    /// `wait traced`, `measure`, `screenshot FILE.png`, `lab student|reference|difference`.
    #[arg(long = "step", value_name = "STEP", requires = "frames")]
    steps: Vec<String>,
    /// A file of steps, one a line (`#` comments); run before any --step.
    #[arg(long, value_name = "FILE", requires = "frames")]
    script: Option<PathBuf>,
    /// Print frame times, frames per second and the UI's share at the end.
    #[arg(long)]
    stats: bool,
    /// The window's inner size, WIDTHxHEIGHT (default: as last time, else 1280x720).
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    size: Option<[u32; 2]>,
    /// Lab mode: the lab in this folder (`mirador lab new`), its scene drawn with the student's
    /// file and redrawn when it is saved; L switches your image, the reference, their difference.
    #[arg(long, value_name = "DIR", conflicts_with = "scene")]
    lab: Option<PathBuf>,
}

fn parse_pixel(text: &str) -> Result<[u32; 2], String> {
    let (x, y) = text.split_once(',').ok_or("expected X,Y, e.g. 320,180")?;
    match (x.trim().parse::<u32>(), y.trim().parse::<u32>()) {
        (Ok(x), Ok(y)) => Ok([x, y]),
        _ => Err("each coordinate must be a whole number of pixels from 0".into()),
    }
}

fn parse_size(text: &str) -> Result<[u32; 2], String> {
    let (w, h) = text.split_once(['x', 'X', '×']).ok_or("expected WIDTHxHEIGHT, e.g. 1280x720")?;
    let side = |s: &str| s.trim().parse::<u32>().ok().filter(|v| (64..=8192).contains(v));
    match (side(w), side(h)) {
        (Some(w), Some(h)) => Ok([w, h]),
        _ => Err("each side must be a whole number of pixels from 64 to 8192".into()),
    }
}

#[derive(clap::Args, Default)]
struct TraceArgs {
    /// Anti-aliasing (default: the scene's `trace.anti_aliasing`, else one ray per pixel centre).
    #[arg(long, value_enum)]
    aa: Option<AntiAliasing>,
    /// Rays per pixel for `regular` and `jittered`: a square number (1, 4, 9, 16, …).
    #[arg(long)]
    spp: Option<u32>,
    /// Deepest reflection/refraction recursion.
    #[arg(long)]
    max_depth: Option<u32>,
    /// Acceleration structure.
    #[arg(long, value_enum)]
    accel: Option<AccelKind>,
    /// Seed of the jittered pattern.
    #[arg(long)]
    seed: Option<u64>,
    /// Worker threads (default: one per core).
    #[arg(long)]
    threads: Option<usize>,
}

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    stop_quietly_when_the_reader_stops();
    let cli = Cli::parse();
    let result = match cli.command {
        Some(Command::Render { scene, output, exr }) => render(scene, &output, exr.as_deref()),
        Some(Command::Trace { scene, trace: options, output, exr }) => trace(scene, options, &output, exr.as_deref()),
        Some(Command::Compare { scene, trace, output, raster_out, trace_out, error_out, exr, json }) => {
            compare(scene, trace, &output, [raster_out, trace_out, error_out], (exr.as_deref(), json.as_deref()))
        }
        Some(Command::Explain { scene, trace, pixel, json }) => explain(scene, trace, pixel, json.as_deref()),
        Some(Command::Budget { scene, trace, sheet, json }) => budget(scene, trace, sheet.as_deref(), json.as_deref()),
        Some(Command::View(args)) => view(args),
        Some(Command::Lab { command }) => return lab(command),
        Some(Command::Diff { reference, test, mask, json }) => {
            diff(&reference, &test, mask.as_deref(), json.as_deref())
        }
        Some(Command::Copy { scene, dir }) => copy(&scene, &dir),
        Some(Command::Link { page, command }) => page_link(&command).and_then(|linked| match linked {
            Linked::Page(link) => {
                println!("{page}{}", link.query());
                Ok(())
            }
            Linked::CommandLine(why) => bail!("the page cannot show this: {why}"),
        }),
        Some(Command::Book { args }) => return book(&args),
        None => view(ViewArgs::default()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error:#}");
            ExitCode::FAILURE
        }
    }
}

/// A reader that stops reading (`mirador lab list | head -1`) closes the pipe, and Rust's print
/// macros then panic. Like other command-line tools, Mirador stops quietly instead, with the
/// status a shell gives a writer the closed pipe ends (128 + SIGPIPE).
fn stop_quietly_when_the_reader_stops() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let message = payload.downcast_ref::<String>().map(String::as_str).or(payload.downcast_ref::<&str>().copied());
        // "Broken pipe" on Unix; Windows says the pipe "is being closed" (os error 232).
        let closed = |m: &str| m.contains("Broken pipe") || m.contains("os error 232");
        if message.is_some_and(|m| m.starts_with("failed printing to stdout") && closed(m)) {
            std::process::exit(141);
        }
        default(info);
    }));
}

/// The page's address for a command's words after `mirador`, made by the CLI's own parser:
/// `render` is the raster view, `trace` the traced one, `compare` and `explain` the split view,
/// `budget` the budget's panel; the trace options become the settings they set. The image's size
/// is not said: the page draws at its window's. A command the page cannot show (a scene of the
/// student's own, `diff`, `lab`) is said why; one that Mirador itself refuses (an unknown option,
/// a setting the scene does not take) is an error.
fn page_link(words: &[String]) -> anyhow::Result<Linked> {
    let cli = Cli::try_parse_from(std::iter::once("mirador").chain(words.iter().map(String::as_str))).map_err(|e| {
        // Clap's message, up to its usage lines.
        let text = e.to_string();
        let message: Vec<&str> = text.lines().take_while(|l| !l.is_empty()).map(str::trim).collect();
        anyhow::anyhow!("{}", message.join(" ").trim_start_matches("error: "))
    })?;
    let inspect = || Some("inspect the pixel (I, then a click on it)".to_owned());
    // The scene's arguments, the trace options, the view, whether to measure the budget, and
    // what to do in the page after.
    let (args, trace, view, budget, then) = match cli.command {
        None => return Ok(Linked::Page(PageLink::default())),
        Some(Command::View(args)) if args.lab.is_some() => {
            return Ok(Linked::CommandLine(
                "a lab's folder of your own: the page opens its labs from the Lab menu".into(),
            ));
        }
        Some(Command::View(args)) => {
            let scene = SceneArgs { scene: args.scene, width: None, height: None, set: args.set, stats: false };
            (scene, TraceArgs::default(), None, false, None)
        }
        Some(Command::Render { scene, .. }) => (scene, TraceArgs::default(), Some("raster"), false, None),
        Some(Command::Trace { scene, trace, .. }) => (scene, trace, Some("traced"), false, None),
        Some(Command::Compare { scene, trace, .. }) => (scene, trace, Some("split"), false, None),
        Some(Command::Explain { scene, trace, .. }) => (scene, trace, Some("split"), false, inspect()),
        Some(Command::Budget { scene, trace, .. }) => (scene, trace, None, true, None),
        Some(_) => return Ok(Linked::CommandLine("the page has no such command".into())),
    };
    let scene = match args.scene.as_deref().map(PageLink::builtin_scene) {
        None => "showcase.toml".to_owned(),
        Some(Ok(scene)) => scene,
        Some(Err(why)) => return Ok(Linked::CommandLine(why)),
    };
    let mut set = args.set.clone();
    set.extend(trace_settings(&args, &trace).context(words.join(" "))?);
    Ok(Linked::Page(PageLink { scene: Some(scene), set, view, budget, then }))
}

/// The scene loaded with `--set` as the command would load it (so that a setting it refuses is
/// an error here too), and its trace options as the settings they change, `trace.KEY=VALUE`: the
/// settings before and after [`apply_trace_args`], compared field by field.
fn trace_settings(args: &SceneArgs, trace: &TraceArgs) -> anyhow::Result<Vec<String>> {
    let scene = prepare(&SceneArgs { stats: false, ..args.clone() }, &mut Stopwatch::default())?;
    let mut after = scene.settings.clone();
    apply_trace_args(&mut after, trace)?;
    let table = |settings: &RenderSettings| toml::Value::try_from(&settings.trace).map_err(anyhow::Error::from);
    let (before, after) = (table(&scene.settings)?, table(&after)?);
    let (Some(before), Some(after)) = (before.as_table(), after.as_table()) else {
        bail!("the trace settings are no table")
    };
    Ok(after
        .iter()
        .filter(|(key, value)| before.get(*key) != Some(value))
        .map(|(key, value)| format!("trace.{key}={value}"))
        .collect())
}

/// `mirador book`: mdBook's preprocessor protocol. `supports RENDERER` answers by the exit
/// status; otherwise the book comes as JSON on standard input and goes back on standard output,
/// and the repository files the chapters link are copied into the book's `source/`.
fn book(args: &[String]) -> ExitCode {
    if let [verb, renderer] = args
        && verb == "supports"
    {
        return if renderer == "html" { ExitCode::SUCCESS } else { ExitCode::FAILURE };
    }
    match preprocess_book() {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: mirador book: {error:#}");
            ExitCode::FAILURE
        }
    }
}

fn preprocess_book() -> anyhow::Result<()> {
    use std::io::Read as _;
    let mut input = String::new();
    std::io::stdin().read_to_string(&mut input).context("reading the book from mdBook")?;
    let context: serde_json::Value = serde_json::from_str(&input).context("mdBook's input is not JSON")?;
    let root = PathBuf::from(context[0]["root"].as_str().unwrap_or("."));
    let config = &context[0]["config"]["preprocessor"]["mirador"];
    let repository = config["repository"].as_str().map_or_else(|| root.clone(), |r| root.join(r));
    let source = config["source"].as_str().filter(|s| !s.is_empty()).map(str::to_owned);
    // The chapters' commands name their files from the repository's root, as a student runs them.
    std::env::set_current_dir(&repository).with_context(|| format!("{}: the repository", repository.display()))?;
    let options = mirador::course::book::Options { repository: repository.clone(), source, link_of: &page_link };
    let rewritten = mirador::course::book::preprocess(&input, &options)?;
    let book_src = root.join(context[0]["config"]["book"]["src"].as_str().unwrap_or("src"));
    rewritten.write_copies(&repository, &book_src)?;
    println!("{}", rewritten.book);
    Ok(())
}

/// `mirador copy SCENE DIR`.
fn copy(scene: &Path, dir: &Path) -> anyhow::Result<()> {
    let builtin = mirador::scene::builtin_path(&scene.to_string_lossy());
    let scene = if scene.exists() || !builtin.exists() { scene.to_path_buf() } else { builtin };
    let copied = mirador::scene::file::copy::copy(&scene, dir).map_err(anyhow::Error::msg)?;
    for file in &copied.files {
        println!("wrote {}", dir.join(file).display());
    }
    Ok(())
}

/// `mirador lab …`: its own exit status (`check` fails when a test does).
fn lab(command: LabCommand) -> ExitCode {
    use mirador::lab::{self, autograder, check, folder, run, summary};
    let outcome = match command {
        LabCommand::List => {
            for lab in lab::catalog() {
                println!("{:<18} chapter {:<2} {}", lab.name, lab.chapter, lab.title);
            }
            Ok(true)
        }
        LabCommand::New { lab, dir, solution } => lab::find(&lab).and_then(|lab| {
            let written = folder::create(&lab, &dir, solution)?;
            for path in written {
                println!("wrote {}", path.display());
            }
            Ok(true)
        }),
        LabCommand::Check { dir, lab, tests, points, time_limit, results, format } => {
            let time_limit =
                std::time::Duration::try_from_secs_f64(time_limit).unwrap_or(std::time::Duration::from_secs(30));
            let results = results.map(|path| (path, format));
            lab_check(check::Options { dir, lab, hidden: tests, points, time_limit, results })
        }
        LabCommand::Autograder { lab, dir, service, tests, points, binary, time_limit } => {
            lab::find(&lab).and_then(|lab| {
                let binary = match binary {
                    Some(binary) => binary,
                    None => std::env::current_exe().map_err(|e| format!("the running binary: {e}"))?,
                };
                let options = autograder::Options { dir, service, hidden: tests, points, binary, time_limit };
                for path in autograder::write(&lab, &options)? {
                    println!("wrote {}", path.display());
                }
                Ok(true)
            })
        }
        LabCommand::Summary { results, out } => summary::read(&results).and_then(|submissions| {
            let summary = summary::summarise(submissions);
            std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;
            for (name, text) in [("summary.html", summary::html(&summary)), ("summary.md", summary::markdown(&summary))]
            {
                let path = out.join(name);
                output::write_atomically(text.as_bytes(), &path).map_err(|e| format!("{}: {e}", path.display()))?;
                println!("wrote {}", path.display());
            }
            println!("{} submissions", summary.submissions.len());
            Ok(true)
        }),
        LabCommand::Passed { results, index } => {
            std::fs::read_to_string(&results).map_err(|e| format!("{}: {e}", results.display())).and_then(|text| {
                let json: serde_json::Value =
                    serde_json::from_str(&text).map_err(|e| format!("{}: {e}", results.display()))?;
                let test = json["tests"]
                    .get(index)
                    .ok_or_else(|| format!("{}: there is no test {index}", results.display()))?;
                println!("{}: {}", test["name"].as_str().unwrap_or("?"), test["output"].as_str().unwrap_or(""));
                // A test worth nothing (a teacher's test in error) costs nobody a point.
                Ok(test["status"] == "passed" || test["max_score"].as_f64() == Some(0.0))
            })
        }
        LabCommand::Run { dir, from, tests, lab: name, file, key } => {
            let name = match name {
                Some(name) => Ok(name),
                None => check::LabFolder::read(&dir).map(|folder| folder.lab),
            };
            name.and_then(|name| {
                let lab = lab::find(&name)?;
                let text = if key {
                    lab.solution()
                } else {
                    let path = file.unwrap_or_else(|| dir.join(&lab.file));
                    std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?
                };
                let tests = run::tests(&lab, tests.as_deref())?;
                run::run(&lab, &text, &tests, from, &dir, !key).map(|()| true)
            })
        }
    };
    match outcome {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
        Err(error) => {
            eprintln!("error: {error}");
            ExitCode::from(2)
        }
    }
}

/// `mirador lab check`: the report printed, and with `--results` a result file written even when
/// the submission cannot be checked at all (it says why). Whether every test passed.
fn lab_check(options: mirador::lab::check::Options) -> Result<bool, String> {
    use mirador::lab::{check, report};
    let checked = check::check(&options);
    if let (Err(why), Some((path, format))) = (&checked, &options.results) {
        let json = report::failure_json(*format, why);
        if let Err(e) = output::write_atomically(json.as_bytes(), path) {
            eprintln!("error: {}: {e}", path.display());
        }
    }
    checked.map(|report| {
        let dir = &options.dir;
        print!("{}", report::text(&report));
        println!("(written: {} and {})", dir.join("results.json").display(), dir.join("report.md").display());
        report.passed()
    })
}

fn diff(reference: &Path, test: &Path, mask: Option<&Path>, json: Option<&Path>) -> anyhow::Result<()> {
    let read = |path: &Path| -> anyhow::Result<image::RgbaImage> {
        Ok(image::open(path).with_context(|| format!("{}: cannot read the image", path.display()))?.to_rgba8())
    };
    let (a, b) = (read(reference)?, read(test)?);
    let difference = mirador::compare::difference(&a, &b)
        .with_context(|| format!("{} and {}", reference.display(), test.display()))?;
    let mask = match mask {
        Some(path) => {
            let m = read(path)?;
            if m.dimensions() != a.dimensions() {
                bail!(
                    "{}: the mask is {}×{}, the images {}×{}",
                    path.display(),
                    m.width(),
                    m.height(),
                    a.width(),
                    a.height()
                );
            }
            Some(m.pixels().map(|p| p[0] > 0 || p[1] > 0 || p[2] > 0).collect::<Vec<bool>>())
        }
        None => None,
    };
    let figures = mirador::compare::Figures::of(&difference.flip_errors, a.width(), a.height(), mask.as_deref());
    report_figures(&figures, beyond_rounding(&a, &b, mask.as_deref()), difference.psnr_db, json)
}

/// The mean FLIP of `test` against `reference` beyond rounding (under `mask`, where one is given):
/// pixels within [`mirador::budget::ROUNDING_LEVELS`] levels in every channel count as equal, as
/// `budget` and the tests count them. The part of the plain mean it leaves out is what another
/// CPU, rounding its last bits differently, can move.
fn beyond_rounding(reference: &image::RgbaImage, test: &image::RgbaImage, mask: Option<&[bool]>) -> f32 {
    let difference = mirador::compare::difference_beyond(reference, test, mirador::budget::ROUNDING_LEVELS)
        .expect("the caller compared the two images already");
    let figures = mirador::compare::Figures::of(&difference.flip_errors, reference.width(), reference.height(), mask);
    figures.masked_mean.unwrap_or(figures.mean)
}

/// Prints FLIP figures, or writes them as JSON (`-`: standard output instead).
fn report_figures(
    figures: &mirador::compare::Figures,
    beyond_rounding: f32,
    psnr_db: f64,
    json: Option<&Path>,
) -> anyhow::Result<()> {
    let value = serde_json::json!({
        "flip_mean": figures.mean,
        "flip_mean_beyond_rounding": beyond_rounding,
        "worst_region": { "flip_mean": figures.worst_region, "x": figures.worst_region_at[0], "y": figures.worst_region_at[1], "side": mirador::compare::REGION },
        "masked_flip_mean": figures.masked_mean,
        "psnr_db": if psnr_db.is_finite() { Some(psnr_db) } else { None },
    });
    let text = serde_json::to_string_pretty(&value).expect("figures serialise");
    match json {
        Some(path) if path.as_os_str() == "-" => println!("{text}"),
        _ => {
            let [x, y] = figures.worst_region_at;
            let levels = mirador::budget::ROUNDING_LEVELS;
            let beyond =
                format!("beyond rounding: {beyond_rounding:.5} (pixels within {levels} levels counted as equal)");
            println!("FLIP mean: {:.5}", figures.mean);
            if figures.masked_mean.is_none() {
                println!("FLIP mean {beyond}");
            }
            println!("worst {0}×{0} region: {1:.5} at ({x}, {y})", mirador::compare::REGION, figures.worst_region);
            if let Some(masked) = figures.masked_mean {
                println!("FLIP mean under the mask: {masked:.5}");
                println!("FLIP mean under the mask {beyond}");
            }
            println!("PSNR: {psnr_db:.2} dB");
            if let Some(path) = json {
                output::write_atomically(text.as_bytes(), path)
                    .with_context(|| format!("writing {}", path.display()))?;
            }
        }
    }
    Ok(())
}

fn view(args: ViewArgs) -> anyhow::Result<()> {
    use mirador::viewer::{ViewerOptions, run, script};
    if let Some(path) = &args.screenshot {
        check_png(path)?;
    }
    let mut steps = match &args.script {
        Some(path) => script::parse_file(path)?,
        None => Vec::new(),
    };
    for step in &args.steps {
        steps.push(script::parse(step)?);
    }
    run(ViewerOptions {
        scene: args.scene,
        set: args.set,
        frames: args.frames,
        screenshot: args.screenshot,
        steps,
        stats: args.stats,
        size: args.size,
        lab: args.lab,
    })
}

/// Every image output must be a PNG; checked before any work is done.
fn check_png(path: &Path) -> anyhow::Result<()> {
    check_extension(path, "png")
}

/// `--exr` outputs must be `.exr` files; checked before any work is done.
fn check_exr(path: Option<&Path>) -> anyhow::Result<()> {
    path.map_or(Ok(()), |path| check_extension(path, "exr"))
}

fn check_extension(path: &Path, wanted: &str) -> anyhow::Result<()> {
    let extension = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if extension.as_deref() != Some(wanted) {
        bail!("{}: the output must be a .{wanted} file", path.display());
    }
    Ok(())
}

fn write_png(image: &image::RgbaImage, path: &Path) -> anyhow::Result<()> {
    output::write_png_atomically(image, path).with_context(|| format!("{}: cannot write the image", path.display()))
}

fn write_exr(image: &LinearImage, path: &Path) -> anyhow::Result<()> {
    image.write_exr_atomically(path).with_context(|| format!("{}: cannot write the image", path.display()))
}

fn explain(args: SceneArgs, trace_args: TraceArgs, [x, y]: [u32; 2], json: Option<&Path>) -> anyhow::Result<()> {
    let mut clock = Stopwatch::default();
    let mut scene = prepare(&args, &mut clock)?;
    apply_trace_args(&mut scene.settings, &trace_args)?;
    let gpu = Gpu::headless()?;
    gpu.check_image_size((scene.camera.width, scene.camera.height))?;
    let explanation = gpu.checked(|| mirador::explain::explain(&gpu, &scene, &scene.settings, (x, y)))??;
    match json {
        Some(path) if path.as_os_str() == "-" => println!("{}", explanation.to_json()),
        Some(path) => {
            output::write_atomically(explanation.to_json().as_bytes(), path)
                .with_context(|| format!("writing {}", path.display()))?;
            print!("{}", mirador::explain::text::render(&explanation));
        }
        None => print!("{}", mirador::explain::text::render(&explanation)),
    }
    Ok(())
}

/// Loads the scene (or the built-in showcase), applies `--set` and the size options.
fn prepare(args: &SceneArgs, clock: &mut Stopwatch) -> anyhow::Result<Scene> {
    // `camera.…`, `lights.…`, `materials.…`, `objects.…`, `world.…` and `settings.…` override the
    // scene file's own values before it is read; any other key is a render setting.
    let (overrides, settings): (Vec<String>, Vec<String>) =
        args.set.iter().cloned().partition(|a| overrides::is_scene_override(a));
    let path = args.scene.clone().unwrap_or_else(|| mirador::scene::builtin_path("showcase.toml"));
    let mut scene = clock.time("scene load", || overrides::load(&path, &overrides))?;
    for assignment in &settings {
        scene.settings.set(assignment).context("--set")?;
    }
    scene.camera.width = args.width.unwrap_or(scene.camera.width);
    scene.camera.height = args.height.unwrap_or(scene.camera.height);
    scene.camera.validate().context("--width/--height")?;
    // `bump.method = "displacement"`: the height fields' surfaces made as triangles, for both
    // renderers alike.
    let displaced = clock.time("displacement", || mirador::texture::displacement::displace(&mut scene));
    if let Some(line) = displaced.summary().filter(|_| args.stats) {
        println!("{line}");
    }
    Ok(scene)
}

/// Applies the trace options over the scene's settings.
fn apply_trace_args(settings: &mut RenderSettings, args: &TraceArgs) -> anyhow::Result<()> {
    let trace = &mut settings.trace;
    if let Some(aa) = args.aa {
        trace.anti_aliasing = aa;
    }
    if let Some(spp) = args.spp {
        let side = (spp as f64).sqrt().round() as u32;
        if side * side != spp || side == 0 {
            bail!("--spp {spp}: the rays per pixel form a square grid, so give a square number (1, 4, 9, 16, …)");
        }
        trace.samples = side;
        if args.aa.is_none() && trace.anti_aliasing == AntiAliasing::Center && spp > 1 {
            trace.anti_aliasing = AntiAliasing::Jittered;
        }
    }
    if let Some(depth) = args.max_depth {
        trace.max_depth = depth;
    }
    if let Some(accel) = args.accel {
        trace.accelerator = accel;
    }
    if let Some(seed) = args.seed {
        trace.seed = seed;
    }
    settings.validate().context("trace options")?;
    Ok(())
}

fn render(args: SceneArgs, output_path: &Path, exr_path: Option<&Path>) -> anyhow::Result<()> {
    check_png(output_path)?;
    check_exr(exr_path)?;
    let mut clock = Stopwatch::default();
    let scene = prepare(&args, &mut clock)?;
    let (image, linear, adapter) = rasterize(&scene, &mut clock, args.stats, exr_path.is_some())?;
    clock.time("encode + write", || write_png(&image, output_path))?;
    if let (Some(linear), Some(path)) = (linear, exr_path) {
        clock.time("EXR encode + write", || write_exr(&linear, path))?;
    }
    if args.stats {
        println!("adapter: {adapter}");
        print_scene(&scene);
        println!("{}", clock.report());
    }
    Ok(())
}

/// The rasterizer's image of `scene` with its settings; returns it, with `linear` its HDR target
/// (the radiance before the output transform), and the adapter's name. With `timed_frames`,
/// also a second frame (what an interactive frame costs, with everything the first one cached)
/// and a third with each pass submitted and timed on its own. The size is checked against the
/// device's limits before anything is created, and every GPU error after that (validation, out
/// of memory) comes back as an error, not a panic.
fn rasterize(
    scene: &Scene,
    clock: &mut Stopwatch,
    timed_frames: bool,
    linear: bool,
) -> anyhow::Result<(image::RgbaImage, Option<LinearImage>, String)> {
    let gpu = clock.time("device", Gpu::headless)?;
    let size = (scene.camera.width, scene.camera.height);
    gpu.check_image_size(size)?;
    let (pixels, radiance) = gpu.checked(|| {
        let (mut renderer, mut targets, output) = clock.time("pipelines and upload", || {
            let renderer = Renderer::new(&gpu, scene, OUTPUT_FORMAT);
            let targets = FrameTargets::new(&gpu.device, drawn_size(size, scene.settings.raster.render_scale));
            let output = GpuTexture::target(&gpu.device, "cli::output", size, OUTPUT_FORMAT);
            gpu.wait();
            (renderer, targets, output)
        });
        // The first frame also pays for the driver's lazy pipeline compilation and fills the
        // caches (shadow maps, tessellations); the second is what an interactive frame costs.
        let mut frame = |renderer: &mut Renderer| {
            let report = renderer.render(&gpu, scene, &scene.settings, &mut targets, &output.view);
            gpu.wait();
            report
        };
        let first = clock.time("first frame", || frame(&mut renderer));
        if timed_frames {
            let second = clock.time("frame", || frame(&mut renderer));
            renderer.profile = true;
            renderer.invalidate_shadows();
            let profiled = frame(&mut renderer);
            let meshes = renderer.scene_gpu().geometry.mesh_count();
            print_frame_stats(&first, &second, &profiled, meshes, renderer.shader_variants());
            if let Some(report) = renderer.tessellation_report() {
                println!("{}", report.summary());
            }
        }
        clock.time("readback", || {
            let pixels = readback::read_rgba8(&gpu.device, &gpu.queue, &output.texture)?;
            let hdr = &targets.hdr.texture;
            let radiance = if linear {
                Some((readback::read_rgb16f(&gpu.device, &gpu.queue, hdr)?, (hdr.width(), hdr.height())))
            } else {
                None
            };
            Ok::<_, readback::ReadbackError>((pixels, radiance))
        })
    })??;
    let image = image::RgbaImage::from_raw(size.0, size.1, pixels).expect("readback returns one RGBA8 texel per pixel");
    let linear = match radiance {
        Some((pixels, (width, height))) => {
            if (width, height) != size {
                log::warn!(
                    "raster.render_scale = {}: the EXR holds the image as drawn, {width}×{height}, before the \
                     present pass upscales it to {}×{}",
                    scene.settings.raster.render_scale,
                    size.0,
                    size.1
                );
            }
            Some(LinearImage::new(width, height, pixels)?)
        }
        None => None,
    };
    Ok((image, linear, gpu.describe()))
}

/// `--stats` for the rasterizer: what the frames drew and where a frame's time goes.
fn print_frame_stats(
    first: &FrameReport,
    second: &FrameReport,
    profiled: &FrameReport,
    meshes: usize,
    variants: usize,
) {
    println!(
        "raster: {} triangles per view in {meshes} meshes, {variants} shader variants, drawn at {}×{}",
        first.triangles, first.drawn_size.0, first.drawn_size.1
    );
    println!("what each pass did, in the first frame | the second (what it kept):");
    for pass in first.passes.iter().filter(|p| !p.figures.is_empty()) {
        let figures: Vec<String> = pass
            .figures
            .iter()
            .map(|(name, value)| match second.figure(pass.name, name) {
                Some(again) => format!("{name} {value} | {again}"),
                None => format!("{name} {value}"),
            })
            .collect();
        println!("{:>20}: {}", pass.name, figures.join(", "));
    }
    println!("passes (each submitted and waited for on its own, shadow maps redrawn):");
    for pass in &profiled.passes {
        let time = pass.time.unwrap_or_default();
        println!("{:>20}: {:9.3} ms", pass.name, time.as_secs_f64() * 1e3);
    }
}

/// The tracer's radiance image of `scene` with its settings.
fn ray_trace(
    scene: &Scene,
    threads: Option<usize>,
    clock: &mut Stopwatch,
    stats: bool,
) -> anyhow::Result<RadianceImage> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads.unwrap_or(0)).build().context("--threads")?;
    let tracer = clock.time("build", || Tracer::new(scene, &scene.settings));
    let control = RenderControl { cancel: None, progress: true };
    let (radiance, trace_stats) = clock.time("trace", || pool.install(|| tracer.render(&control)))?;
    if stats {
        println!("threads: {}", pool.current_num_threads());
        println!("{}", tracer.accelerator_stats());
        println!("{trace_stats}");
    }
    Ok(radiance)
}

/// The tracer's radiance for `--exr`.
fn linear_of(radiance: RadianceImage) -> anyhow::Result<LinearImage> {
    Ok(LinearImage::new(radiance.width, radiance.height, radiance.pixels)?)
}

fn trace(args: SceneArgs, trace_args: TraceArgs, output_path: &Path, exr_path: Option<&Path>) -> anyhow::Result<()> {
    check_png(output_path)?;
    check_exr(exr_path)?;
    let mut clock = Stopwatch::default();
    let mut scene = prepare(&args, &mut clock)?;
    apply_trace_args(&mut scene.settings, &trace_args)?;
    if args.stats {
        print_scene(&scene);
    }
    let radiance = ray_trace(&scene, trace_args.threads, &mut clock, args.stats)?;
    clock.time("encode + write", || {
        write_png(&radiance.to_rgba8(mirador::output::OutputTransform::of(&scene.settings)), output_path)
    })?;
    if let Some(path) = exr_path {
        let linear = linear_of(radiance)?;
        clock.time("EXR encode + write", || write_exr(&linear, path))?;
    }
    if args.stats {
        println!("{}", clock.report());
    }
    Ok(())
}

fn compare(
    args: SceneArgs,
    trace_args: TraceArgs,
    sheet_path: &Path,
    extra: [Option<PathBuf>; 3],
    (exr_path, json): (Option<&Path>, Option<&Path>),
) -> anyhow::Result<()> {
    check_png(sheet_path)?;
    for path in extra.iter().flatten() {
        check_png(path)?;
    }
    check_exr(exr_path)?;
    let mut clock = Stopwatch::default();
    let mut scene = prepare(&args, &mut clock)?;
    apply_trace_args(&mut scene.settings, &trace_args)?;
    let (raster, raster_linear, adapter) = rasterize(&scene, &mut clock, false, exr_path.is_some())?;
    let traced_radiance = ray_trace(&scene, trace_args.threads, &mut clock, args.stats)?;
    let traced = traced_radiance.to_rgba8(mirador::output::OutputTransform::of(&scene.settings));
    let difference = mirador::compare::difference(&traced, &raster).expect("both images have the camera's size");
    if json.is_none_or(|path| path.as_os_str() != "-") {
        println!("adapter: {adapter}");
    }
    let figures = mirador::compare::Figures::of(&difference.flip_errors, traced.width(), traced.height(), None);
    report_figures(&figures, beyond_rounding(&traced, &raster, None), difference.psnr_db, json)?;
    let panels = [
        Panel::new("raster", raster.clone()),
        Panel::new("ray traced", traced.clone()),
        Panel::new(format!("FLIP {:.4}", difference.flip_mean), difference.error_map.clone()),
    ];
    let sheet_image = with_footer(&sheet(&panels), &flip_legend(scene.camera.width.clamp(200, 400)));
    let [raster_out, trace_out, error_out] = extra;
    for (image, path) in [(&raster, raster_out), (&traced, trace_out), (&difference.error_map, error_out)] {
        if let Some(path) = path {
            write_png(image, &path)?;
        }
    }
    clock.time("encode + write", || write_png(&sheet_image, sheet_path))?;
    if let (Some(raster_linear), Some(path)) = (raster_linear, exr_path) {
        let both = LinearImage::side_by_side(&raster_linear, &linear_of(traced_radiance)?);
        clock.time("EXR encode + write", || write_exr(&both, path))?;
    }
    if args.stats {
        println!("{}", clock.report());
    }
    Ok(())
}

fn budget(args: SceneArgs, trace_args: TraceArgs, sheet: Option<&Path>, json: Option<&Path>) -> anyhow::Result<()> {
    if let Some(path) = sheet {
        check_png(path)?;
    }
    let mut clock = Stopwatch::default();
    let mut scene = prepare(&args, &mut clock)?;
    apply_trace_args(&mut scene.settings, &trace_args)?;
    // Bump and parallax mapping are measured against the displaced surface they stand for.
    let reference = mirador::budget::reference_scene(&scene, &scene.settings);
    let traced_radiance = ray_trace(&reference, trace_args.threads, &mut clock, args.stats)?;
    let traced = traced_radiance.to_rgba8(mirador::output::OutputTransform::of(&scene.settings));
    let gpu = clock.time("device", Gpu::headless)?;
    gpu.check_image_size((scene.camera.width, scene.camera.height))?;
    // Twelve frames for the showcase, each tracing its terms: seconds on a CPU rasterizer. The
    // bar is drawn only where standard error is a terminal.
    let bar = indicatif::ProgressBar::new(0).with_style(
        indicatif::ProgressStyle::with_template("budget [{bar:30}] {pos}/{len} frames, {elapsed}: {wide_msg}")
            .expect("the progress template is valid")
            .progress_chars("=> "),
    );
    let mut drawn = |frame: mirador::budget::Drawn| {
        bar.set_length(frame.frames as u64);
        bar.set_position(frame.done as u64);
        bar.set_message(format!("the last one {}", frame.what));
    };
    let scenes = (&scene, &*reference);
    let budget = gpu.checked(|| {
        clock.time("raster frames", || {
            mirador::budget::budget_reporting(&gpu, scenes, &scene.settings, traced, &mut drawn)
        })
    })?;
    bar.finish_and_clear();
    let text = serde_json::to_string_pretty(&budget.json()).expect("the budget serialises");
    match json {
        Some(path) if path.as_os_str() == "-" => println!("{text}"),
        _ => {
            print!("{}", budget.report());
            if let Some(path) = json {
                output::write_atomically(text.as_bytes(), path)
                    .with_context(|| format!("writing {}", path.display()))?;
            }
        }
    }
    if let Some(path) = sheet {
        clock.time("encode + write", || write_png(&mirador::budget::sheet::sheet(&budget), path))?;
    }
    if args.stats {
        println!("{}", clock.report());
    }
    Ok(())
}

fn print_scene(scene: &Scene) {
    println!(
        "scene: {} objects, {} lights, {}×{} pixels",
        scene.objects.len(),
        scene.lights.len(),
        scene.camera.width,
        scene.camera.height
    );
}
