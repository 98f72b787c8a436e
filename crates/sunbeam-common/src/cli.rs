//! The one way a Sunbeam tool starts and ends (as ripgrep's `crates/core/main.rs`):
//! parse the command line with clap, print help/version (exit 0), turn a parse
//! error into [`Error::usage`], run the tool, and leave through one exit path
//! ([`crate::error::run_main`]) with the documented exit code.
//!
//! ```no_run
//! # #[derive(clap::Parser)] struct Cli {}
//! # fn run(_: Cli) -> sunbeam_common::Result<()> { Ok(()) }
//! fn main() {
//!     sunbeam_common::cli::main("sunbeam-xxx", run)
//! }
//! ```
//!
//! Length arguments are parsed by clap value parsers built on [`crate::units`]
//! ([`length`], [`positive_length`], [`length_range`], [`pixel_size`]), angles
//! by [`angle`] and sizes in bytes by [`byte_size`], so a bad value is a usage
//! error (exit 1) that names the flag, before the tool runs.

use crate::error::{run_main, Error, Result};
use crate::units;

/// Parse the command line as `C`, then run `body`; never returns.
///
/// - `--help`, `--version`: printed on stdout, exit 0.
/// - a parse error: `TOOL: error: <clap's message and usage>`, exit 1.
/// - `body` returns `Err(e)`: `TOOL: error: <e>`, exit `e`'s code.
/// - `body` panics: exit 4 (a bug).
pub fn main<C: clap::Parser>(tool: &str, body: impl FnOnce(C) -> Result<()>) -> ! {
    run_main(tool, || match parse::<C>()? {
        Some(cli) => body(cli),
        None => Ok(()),
    })
}

/// Parse the command line: `Ok(None)` when help or version was printed.
pub fn parse<C: clap::Parser>() -> Result<Option<C>> {
    parse_from::<C, _, _>(std::env::args_os())
}

/// [`parse`] on given arguments (the first is the program name).
pub fn parse_from<C, I, T>(args: I) -> Result<Option<C>>
where
    C: clap::Parser,
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    match C::try_parse_from(args) {
        Ok(c) => Ok(Some(c)),
        Err(e) if !e.use_stderr() => {
            // --help / --version: clap's text on stdout.
            print!("{e}");
            Ok(None)
        }
        Err(e) => Err(usage_error(&e)),
    }
}

/// A clap parse error as a usage error: clap's own text (message, usage line,
/// hint), without its leading `error: ` (the tool's prefix says it).
pub fn usage_error(e: &clap::Error) -> Error {
    let s = e.to_string();
    let s = s.trim_end();
    Error::usage(s.strip_prefix("error: ").unwrap_or(s))
}

/// A pixel size `DX,DY` in metres (`--pixel-size 65nm` or `65nm,70nm`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PixelSize {
    pub dx: f64,
    pub dy: f64,
}

impl PixelSize {
    pub fn pair(self) -> (f64, f64) {
        (self.dx, self.dy)
    }
}

impl std::fmt::Display for PixelSize {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.dx == self.dy {
            write!(f, "{}", units::format_length(self.dx).replace(' ', ""))
        } else {
            write!(
                f,
                "{},{}",
                units::format_length(self.dx).replace(' ', ""),
                units::format_length(self.dy).replace(' ', "")
            )
        }
    }
}

/// clap value parser: a length with its unit (`20nm`), in metres.
pub fn length(s: &str) -> Result<f64> {
    units::parse_length(s)
}

/// clap value parser: a positive length (`65um`), in metres.
pub fn positive_length(s: &str) -> Result<f64> {
    units::parse_positive_length(s)
}

/// clap value parser: a range of lengths (`380nm..780nm`), in metres.
pub fn length_range(s: &str) -> Result<(f64, f64)> {
    units::parse_length_range(s)
}

/// clap value parser: `LEN` or `LEN,LEN` (dx, dy), both positive.
pub fn pixel_size(s: &str) -> Result<PixelSize> {
    match s.split_once(',') {
        Some((a, b)) => Ok(PixelSize {
            dx: units::parse_positive_length(a)?,
            dy: units::parse_positive_length(b)?,
        }),
        None => {
            let v = units::parse_positive_length(s)?;
            Ok(PixelSize { dx: v, dy: v })
        }
    }
}

/// clap value parser: a finite number in `lo..=hi` (no unit).
pub fn ranged(lo: f64, hi: f64) -> impl Fn(&str) -> std::result::Result<f64, String> + Clone {
    move |s: &str| {
        let v: f64 = s
            .trim()
            .parse()
            .map_err(|_| format!("{s:?} is not a number"))?;
        if v.is_finite() && (lo..=hi).contains(&v) {
            Ok(v)
        } else {
            Err(format!("{v} is outside [{lo}, {hi}]"))
        }
    }
}

/// clap value parser: an angle (`75deg`, `1.3rad`; a bare number is degrees), in radians.
pub fn angle(s: &str) -> Result<f64> {
    units::parse_angle(s)
}

/// clap value parser: a size in bytes, at least 1, with an optional suffix
/// `B`, `KiB`, `MiB` or `GiB` (`64MiB`, `1.5GiB`, `4096`).
pub fn byte_size(s: &str) -> Result<usize> {
    let t = s.trim();
    let (num, mult) = [
        ("GiB", 1usize << 30),
        ("MiB", 1 << 20),
        ("KiB", 1 << 10),
        ("B", 1),
    ]
    .iter()
    .find_map(|(suf, m)| t.strip_suffix(suf).map(|n| (n.trim(), *m)))
    .unwrap_or((t, 1));
    match num.parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 1.0 => Ok((v * mult as f64) as usize),
        _ => Err(Error::usage(
            "not a size: give one such as 64MiB (suffixes B, KiB, MiB, GiB)",
        )),
    }
}

/// clap value parser for an enum of named values (`--model window|tiled`):
/// `names` are shown in `--help` and checked by clap, then parsed with `T::from_str`.
pub fn one_of<T>(names: &'static [&'static str]) -> impl clap::builder::TypedValueParser<Value = T>
where
    T: std::str::FromStr<Err = Error> + Clone + Send + Sync + 'static,
{
    use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
    PossibleValuesParser::new(names.iter().map(|n| PossibleValue::new(*n)))
        .try_map(|s: String| s.parse::<T>())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser, Debug)]
    #[command(name = "t", version)]
    struct Cli {
        #[arg(long, value_parser = pixel_size)]
        pixel_size: Option<PixelSize>,
        #[arg(long, value_parser = positive_length, default_value = "65um")]
        coherence: f64,
        #[arg(long, value_parser = angle, default_value = "75deg", allow_hyphen_values = true)]
        theta: f64,
    }

    #[test]
    fn angles_parse_in_clap() {
        let c = parse_from::<Cli, _, _>(["t"]).unwrap().unwrap();
        assert!((c.theta - 75f64.to_radians()).abs() < 1e-15);
        let c = parse_from::<Cli, _, _>(["t", "--theta", "-0.5rad"])
            .unwrap()
            .unwrap();
        assert_eq!(c.theta, -0.5);
        let e = parse_from::<Cli, _, _>(["t", "--theta", "75furlongs"]).unwrap_err();
        assert_eq!(e.exit_code(), 1);
        assert!(e.to_string().contains("--theta"), "{e}");
    }

    #[test]
    fn byte_sizes() {
        assert_eq!(byte_size("64MiB").unwrap(), 64 << 20);
        assert_eq!(byte_size(" 1.5 GiB ").unwrap(), 3 << 29);
        assert_eq!(byte_size("2KiB").unwrap(), 2048);
        assert_eq!(byte_size("100B").unwrap(), 100);
        assert_eq!(byte_size("4096").unwrap(), 4096);
        for bad in ["", "lots", "0", "0.5MiB", "-1MiB", "inf", "NaN", "64MB"] {
            let e = byte_size(bad).unwrap_err();
            assert_eq!(e.exit_code(), 1, "{bad}");
        }
    }

    #[test]
    fn lengths_parse_in_clap() {
        let c = parse_from::<Cli, _, _>(["t", "--pixel-size", "65nm,70nm"])
            .unwrap()
            .unwrap();
        let p = c.pixel_size.unwrap();
        assert!((p.dx - 65e-9).abs() < 1e-20 && (p.dy - 70e-9).abs() < 1e-20);
        assert!((c.coherence - 65e-6).abs() < 1e-18);
        let c = parse_from::<Cli, _, _>(["t", "--pixel-size", "20nm"])
            .unwrap()
            .unwrap();
        assert_eq!(c.pixel_size.unwrap().dx, c.pixel_size.unwrap().dy);
    }

    #[test]
    fn bad_values_are_usage_errors_naming_the_flag() {
        let e = parse_from::<Cli, _, _>(["t", "--pixel-size", "65"]).unwrap_err();
        assert_eq!(e.exit_code(), 1);
        assert!(e.message.contains("--pixel-size"), "{}", e.message);
        assert!(e.message.contains("has no unit"), "{}", e.message);
        assert!(!e.message.starts_with("error:"), "{}", e.message);
        let e = parse_from::<Cli, _, _>(["t", "--coherence", "-1um"]).unwrap_err();
        assert_eq!(e.exit_code(), 1);
        let e = parse_from::<Cli, _, _>(["t", "--nope"]).unwrap_err();
        assert_eq!(e.exit_code(), 1);
    }

    #[test]
    fn help_and_version_are_not_errors() {
        assert!(parse_from::<Cli, _, _>(["t", "--version"])
            .unwrap()
            .is_none());
    }
}
