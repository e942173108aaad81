//! `cargo bench --bench sweep`: a reduced `isr bench` (the quick sweep of
//! every method on the Cornell box and the hall, 128x128, RSM 128, four
//! animation frames), through the same code, into `target/bench/sweep/`;
//! prints the ratios of `report.md`. Rows already there are reused: delete
//! the folder to measure again.

use isr::bench::{self, BenchArgs};

fn main() -> anyhow::Result<()> {
    let args = BenchArgs {
        scenes: vec!["cornell".into(), "hall".into()],
        width: Some(128),
        height: Some(128),
        rsm: Some(128),
        frames: Some(4),
        timing_frames: Some(3),
        out_dir: std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/bench/sweep"),
        quick: true,
        ..Default::default()
    };
    let plan = args.plan()?;
    let outcome = bench::run(&plan)?;
    println!("{} on {}", outcome.device, outcome.driver);
    print!(
        "{}",
        bench::ratios::ratios_text(&bench::ratios::ratios(&outcome.rows))
    );
    println!(
        "report: {}",
        plan.out_dir.join(bench::files::REPORT).display()
    );
    Ok(())
}
