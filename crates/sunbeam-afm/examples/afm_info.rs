//! Print the channels sunbeam-afm reads from files (debugging aid):
//! `cargo run -p sunbeam-afm --example afm_info -- FILE...`

use std::path::Path;

use sunbeam_afm::{detect, read_file, ReadOptions};

fn main() {
    let opts = ReadOptions {
        pixel_size: Some((1e-9, 1e-9)),
        z_range: Some(1e-6),
        ..Default::default()
    };
    for a in std::env::args().skip(1) {
        let fmt = std::fs::read(&a).ok().and_then(|b| detect(&b));
        match read_file(Path::new(&a), &opts) {
            Ok(chans) => {
                for c in chans {
                    let (lo, hi) = c.field.finite_range().unwrap_or((f64::NAN, f64::NAN));
                    println!(
                        "{a} [{:?}] '{}' {}x{} {:.4e} x {:.4e} {} z {:.4e}..{:.4e} {}{}",
                        fmt.map(|f| f.name()),
                        c.name,
                        c.field.width,
                        c.field.height,
                        c.field.size_x(),
                        c.field.size_y(),
                        c.xy_unit,
                        lo,
                        hi,
                        c.z_unit,
                        if c.is_height { " (height)" } else { "" }
                    );
                }
            }
            Err(e) => println!(
                "{a} [{:?}] error ({:?}): {e}",
                fmt.map(|f| f.name()),
                e.code
            ),
        }
    }
}
