//! `idlc`: command-line front end. Exit status: 0 success, 1 errors in the input, 2 usage errors.
use clap::{Parser, ValueEnum};
use idlc::diag::RenderOptions;
use idlc::driver::{Options, Session};
use idlc::model::Extensibility;
use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Clone, Copy, Debug, ValueEnum)]
enum Ext {
    Final,
    Appendable,
    Mutable,
}

#[derive(Clone, Copy, Debug, ValueEnum, PartialEq)]
enum Emit {
    Rust,
    Json,
}

#[derive(Clone, Copy, Debug, ValueEnum, PartialEq)]
enum Color {
    Auto,
    Always,
    Never,
}

/// IDL 4.2 compiler generating Rust types with #[derive(DdsType)].
#[derive(Parser, Debug)]
#[command(name = "idlc", version, about)]
struct Cli {
    /// IDL files to compile.
    #[arg(required = true)]
    files: Vec<PathBuf>,
    /// Add a directory to the #include search path.
    #[arg(short = 'I', value_name = "DIR")]
    include: Vec<PathBuf>,
    /// Define a macro (NAME or NAME=VALUE).
    #[arg(short = 'D', value_name = "NAME[=VALUE]")]
    define: Vec<String>,
    /// Undefine a macro.
    #[arg(short = 'U', value_name = "NAME")]
    undefine: Vec<String>,
    /// Output directory (default: current directory). Each input FILE.idl produces FILE.rs (or FILE.json).
    #[arg(short = 'o', value_name = "DIR")]
    out_dir: Option<PathBuf>,
    /// Extensibility of types without an explicit annotation.
    #[arg(long, value_enum, default_value = "appendable")]
    default_extensibility: Ext,
    /// Preprocess only; print the result to stdout.
    #[arg(short = 'E')]
    preprocess_only: bool,
    /// Check only; write nothing.
    #[arg(long)]
    check: bool,
    /// Print make-style dependencies (`out: inputs...`) to stdout.
    #[arg(long)]
    deps: bool,
    /// What to generate.
    #[arg(long, value_enum, default_value = "rust")]
    emit: Emit,
    /// Also derive serde::Serialize/Deserialize.
    #[arg(long)]
    serde: bool,
    /// Path of the runtime crate in generated code.
    #[arg(long, default_value = "::dds_runtime")]
    runtime_crate: String,
    /// Colored diagnostics.
    #[arg(long, value_enum, default_value = "auto")]
    color: Color,
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let _ = e.print();
            return ExitCode::from(if e.use_stderr() { 2 } else { 0 });
        }
    };
    let color = match cli.color {
        Color::Always => true,
        Color::Never => false,
        Color::Auto => std::io::stderr().is_terminal() && std::env::var_os("NO_COLOR").is_none(),
    };
    let mut opts = Options {
        include_dirs: cli.include.clone(),
        defines: cli.define.clone(),
        undefines: cli.undefine.clone(),
        default_extensibility: match cli.default_extensibility {
            Ext::Final => Extensibility::Final,
            Ext::Appendable => Extensibility::Appendable,
            Ext::Mutable => Extensibility::Mutable,
        },
        ..Default::default()
    };
    opts.rust.serde = cli.serde;
    opts.rust.runtime_crate = cli.runtime_crate.clone();
    let out_dir = cli.out_dir.clone().unwrap_or_else(|| PathBuf::from("."));
    let render = RenderOptions { color, width: 100 };
    let mut failed = false;
    let stdout = std::io::stdout();
    let mut session = Session::new(opts);
    for file in &cli.files {
        let mut c = session.compile_file(file);
        let ext = if cli.emit == Emit::Json { "json" } else { "rs" };
        let stem = file
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "out".into());
        let out_path = out_dir.join(format!("{stem}.{ext}"));
        let output = if cli.preprocess_only {
            (!c.has_errors()).then(|| c.preprocessed.with_line_markers(&c.db))
        } else if cli.emit == Emit::Json {
            c.json()
        } else {
            c.rust()
        };
        let text = c.render_diagnostics(render);
        if !text.is_empty() {
            eprint!("{text}");
        }
        let Some(output) = output else {
            failed = true;
            continue;
        };
        if cli.deps {
            let deps: Vec<String> = c.files.iter().map(|p| p.display().to_string()).collect();
            let _ = writeln!(stdout.lock(), "{}: {}", out_path.display(), deps.join(" "));
        }
        if cli.preprocess_only {
            let _ = stdout.lock().write_all(output.as_bytes());
        } else if !cli.check {
            if let Err(e) =
                std::fs::create_dir_all(&out_dir).and_then(|_| std::fs::write(&out_path, output))
            {
                eprintln!("error: cannot write {}: {e}", out_path.display());
                failed = true;
            }
        }
    }
    if failed {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}
