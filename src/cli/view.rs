//! `isr view`: the viewer's options (those of `isr render` that make sense
//! in a window, `RunArgs`, plus its own), turned into `RenderSettings` the
//! same way.

use super::options::{MethodArg, RunArgs};
use crate::viewer;
use anyhow::{bail, Result};
use clap::Args;
use std::path::PathBuf;

#[derive(Args)]
pub struct ViewArgs {
    /// The scene, the method shown first (`M` cycles through the interactive
    /// ones), its parameters (`[`/`]` halve and double --tau, `,`/`.`
    /// divide and multiply --vpls by 4), the render size (also the window's
    /// initial size), the start time and the device.
    #[command(flatten)]
    run: RunArgs,
    /// Start with the animation paused (`P` plays it).
    #[arg(long)]
    paused: bool,
    /// Timed input, one command a line: `<seconds> key NAME`, `<seconds>
    /// screenshot PATH.png`, `<seconds> resize W H`, `<seconds> quit`; times
    /// count from the first presented frame.
    #[arg(long)]
    script: Option<PathBuf>,
}

pub fn view(args: ViewArgs) -> Result<()> {
    let run = &args.run;
    run.check_time()?;
    let interactive = viewer::interactive_methods();
    let method = match run.method {
        MethodArg::Gpu(m) if interactive.contains(&m) => m,
        other => {
            let names: Vec<&str> = interactive.iter().map(|m| m.name()).collect();
            bail!(
                "--method {}: isr view shows the methods that render a frame at once on the GPU ({}); \
                 use `isr render --method {}` for it",
                other.name(),
                names.join(", "),
                other.name()
            );
        }
    };
    // The script is read before any window opens, so its errors come first.
    let script = match &args.script {
        Some(path) => viewer::script::load(path)?,
        None => Vec::new(),
    };
    let scene = run.load_scene()?;
    viewer::run(
        &scene,
        viewer::ViewOptions {
            settings: run.settings(method),
            gpu: run.gpu_options(),
            script,
            time: run.time,
            paused: args.paused,
        },
    )
}
