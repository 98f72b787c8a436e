//! Make-style depfiles (`out: in1 in2`), which Ninja reads with `deps = gcc`.

use crate::error::Result;
use crate::output::write_atomic;
use std::path::Path;

/// Escape a path for a Make rule: spaces, '#', '$' and ':' are special.
fn escape(p: &Path) -> String {
    let s = p.to_string_lossy();
    let mut o = String::with_capacity(s.len());
    for ch in s.chars() {
        match ch {
            ' ' => o.push_str("\\ "),
            '#' => o.push_str("\\#"),
            '$' => o.push_str("$$"),
            ':' => o.push_str("\\:"),
            c => o.push(c),
        }
    }
    o
}

/// The depfile text for one or more outputs depending on `inputs`.
pub fn render(outputs: &[&Path], inputs: &[&Path]) -> String {
    let outs: Vec<String> = outputs.iter().map(|p| escape(p)).collect();
    let mut s = outs.join(" ");
    s.push(':');
    for i in inputs {
        s.push_str(" \\\n  ");
        s.push_str(&escape(i));
    }
    s.push('\n');
    // An empty rule per input keeps make going when an input is deleted (like gcc -MP).
    for i in inputs {
        s.push_str(&format!("{}:\n", escape(i)));
    }
    s
}

/// Write a depfile atomically.
pub fn write(depfile: &Path, outputs: &[&Path], inputs: &[&Path]) -> Result<()> {
    write_atomic(depfile, render(outputs, inputs).as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn escapes_and_lists_inputs() {
        let s = render(
            &[Path::new("out dir/a.exr")],
            &[Path::new("in.spm"), Path::new("c:d")],
        );
        assert!(s.starts_with("out\\ dir/a.exr: \\\n  in.spm \\\n  c\\:d\n"));
        assert!(s.contains("\nin.spm:\n"));
    }
}
