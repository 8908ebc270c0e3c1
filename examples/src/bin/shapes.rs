//! `shapes`: the friendly demo. One process runs a publisher of bouncing shapes and a subscriber, each in
//! its own domain participant, so every sample crosses real RTPS over UDP (loopback inside
//! `scripts/isolated`). In a terminal it shows them moving in a window (`dds_examples::shapes_ui`) until
//! q; otherwise, or with `--batch`, it prints positions live and, after `--duration` seconds (default 10) or
//! `--count` received samples, a summary, and exits 0 (1 when a subscriber received nothing).
//!
//!     scripts/isolated cargo run --release --bin shapes
//!     shapes --pub-only --color RED --color GREEN        # interoperates with any shape_main subscriber
//!     shapes --sub-only --topic Circle --duration 30 --batch

use std::io::IsTerminal;
use std::process::ExitCode;

use clap::Parser;
use dds_examples::shapes_demo::{self, args::ShapesArgs, batch};
use dds_examples::{shapes_ui, shutdown};

fn main() -> ExitCode {
    let args = ShapesArgs::parse();
    shutdown::install();
    let mut session = match shapes_demo::session_from_args(&args) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("shapes: {e}");
            return ExitCode::from(2);
        }
    };
    let result = if args.batch || !std::io::stdout().is_terminal() {
        batch::run(&mut session, &args).map_err(|e| e.to_string())
    } else {
        shapes_ui::run(session, &args).map_err(|e| e.to_string())
    };
    match result {
        Ok(code) => ExitCode::from(code),
        Err(e) => {
            eprintln!("shapes: {e}");
            ExitCode::from(2)
        }
    }
}
