fn main() {
    if let Err(e) = isr::cli::run() {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
