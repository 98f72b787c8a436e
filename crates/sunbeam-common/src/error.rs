//! One error type for the tools, carrying the exit code DESIGN.md documents.

use std::fmt;
use std::path::Path;

/// Documented exit codes: 0 ok, 1 usage, 2 input unreadable or invalid,
/// 3 output could not be written, 4 internal; 5 a check the tool was asked to
/// make did not pass (`sunbeam-eval compare` above its tolerance: docs/EVAL.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExitCode {
    Ok = 0,
    Usage = 1,
    Input = 2,
    Output = 3,
    Internal = 4,
    CheckFailed = 5,
    /// stdout's reader left (`tool | head`): a shell's status for a process
    /// killed by SIGPIPE (128 + 13), ended without a message.
    BrokenPipe = 141,
}

/// An error with a message meant for a person and the exit code it maps to.
#[derive(Debug, Clone)]
pub struct Error {
    pub code: ExitCode,
    pub message: String,
}

pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    pub fn usage(msg: impl Into<String>) -> Self {
        Self {
            code: ExitCode::Usage,
            message: msg.into(),
        }
    }
    pub fn input(msg: impl Into<String>) -> Self {
        Self {
            code: ExitCode::Input,
            message: msg.into(),
        }
    }
    /// An input error that names the file: "FILE: what is wrong".
    pub fn input_file(path: &Path, msg: impl fmt::Display) -> Self {
        Self::input(format!("{}: {}", path.display(), msg))
    }
    pub fn output(msg: impl Into<String>) -> Self {
        Self {
            code: ExitCode::Output,
            message: msg.into(),
        }
    }
    /// Writing stdout failed: [`ExitCode::BrokenPipe`] when its reader has
    /// gone, else an output error.
    pub fn stdout(e: std::io::Error) -> Self {
        Self {
            code: if e.kind() == std::io::ErrorKind::BrokenPipe {
                ExitCode::BrokenPipe
            } else {
                ExitCode::Output
            },
            message: format!("stdout: {e}"),
        }
    }
    pub fn output_file(path: &Path, msg: impl fmt::Display) -> Self {
        Self::output(format!("{}: {}", path.display(), msg))
    }
    pub fn internal(msg: impl Into<String>) -> Self {
        Self {
            code: ExitCode::Internal,
            message: msg.into(),
        }
    }
    /// A verdict, not a failure to run: the tool did its work and the check failed
    /// (exit 5). Printed as `TOOL: MESSAGE`, without `error:`.
    pub fn check_failed(msg: impl Into<String>) -> Self {
        Self {
            code: ExitCode::CheckFailed,
            message: msg.into(),
        }
    }
    /// Prefix the message with context, keeping the code.
    pub fn context(mut self, ctx: impl fmt::Display) -> Self {
        self.message = format!("{ctx}: {}", self.message);
        self
    }
    pub fn exit_code(&self) -> i32 {
        self.code as i32
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Error {}

/// Whether a panic is `print!` failing on a closed pipe (its message names
/// stdout and the OS error; std offers no typed payload for it).
fn is_broken_pipe(info: &std::panic::PanicHookInfo<'_>) -> bool {
    let msg = info
        .payload()
        .downcast_ref::<String>()
        .map(String::as_str)
        .or_else(|| info.payload().downcast_ref::<&str>().copied())
        .unwrap_or("");
    msg.starts_with("failed printing to stdout") && msg.contains("os error 32")
}

/// Run a tool's main body: print the error to stderr as `TOOL: error: ...` and
/// exit with its code. A panic (a bug) exits 4 through the default hook's code
/// path being replaced here. This is the one exit path of every tool; tools call
/// it through `sunbeam_common::cli::main`, which parses the command line first.
pub fn run_main(tool: &str, body: impl FnOnce() -> Result<()>) -> ! {
    let tool_name = tool.to_string();
    std::panic::set_hook(Box::new(move |info| {
        if is_broken_pipe(info) {
            // `tool | head`: the reader left. Rust ignores SIGPIPE, so
            // `println!` panics; end as a process killed by SIGPIPE would
            // (128 + 13), without a message, as other Unix tools do.
            std::process::exit(ExitCode::BrokenPipe as i32);
        }
        eprintln!("{tool_name}: internal error (a bug, please report): {info}");
    }));
    let code = match std::panic::catch_unwind(std::panic::AssertUnwindSafe(body)) {
        Ok(Ok(())) => 0,
        Ok(Err(e)) if e.code == ExitCode::CheckFailed => {
            use std::io::Write;
            let _ = std::io::stdout().flush();
            eprintln!("{tool}: {e}");
            e.exit_code()
        }
        // A tool that writes stdout itself ([`Error::stdout`]).
        Ok(Err(e)) if e.code == ExitCode::BrokenPipe => e.exit_code(),
        Ok(Err(e)) => {
            eprintln!("{tool}: error: {e}");
            e.exit_code()
        }
        Err(_) => ExitCode::Internal as i32,
    };
    std::process::exit(code)
}
