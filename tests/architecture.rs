//! The shape of the workspace (docs/dev/ARCHITECTURE.md), checked so it stays:
//!
//! - the physics core `sunbeam-pack` depends on field, optics and common only
//!   (never on the instrument readers, the glTF loader or the render scene);
//! - no crate depends on a tool (a package under `tools/`);
//! - inside a crate, no cycle of `crate::` references between its top modules;
//! - every tool's `main.rs` stays under 150 lines;
//! - no hand-made thread pools (`std::thread::spawn`/`scope`/`Builder`) in the
//!   crates' and tools' sources: parallel work goes through rayon.
//!
//! The crate graph comes from `cargo metadata`. `SUNBEAM_ARCH_ROOT=DIR` checks
//! another checkout instead of this one (that is how the check was shown to fail
//! on the old graph: docs/dev/ARCHITECTURE.md).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    std::env::var_os("SUNBEAM_ARCH_ROOT")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")))
}

/// The workspace's packages: name -> (manifest dir, dependency names of every kind,
/// normal dependency names).
struct Package {
    dir: PathBuf,
    deps_all: BTreeSet<String>,
    deps_normal: BTreeSet<String>,
}

fn workspace() -> BTreeMap<String, Package> {
    let root = root();
    let out = std::process::Command::new(env!("CARGO"))
        .args([
            "metadata",
            "--format-version",
            "1",
            "--no-deps",
            "--offline",
        ])
        .arg("--manifest-path")
        .arg(root.join("Cargo.toml"))
        .output()
        .expect("run cargo metadata");
    assert!(
        out.status.success(),
        "cargo metadata: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("metadata json");
    let mut m = BTreeMap::new();
    for p in v["packages"].as_array().expect("packages") {
        let name = p["name"].as_str().unwrap().to_string();
        let manifest = PathBuf::from(p["manifest_path"].as_str().unwrap());
        let mut deps_all = BTreeSet::new();
        let mut deps_normal = BTreeSet::new();
        for d in p["dependencies"].as_array().unwrap() {
            let dn = d["name"].as_str().unwrap().to_string();
            if d["kind"].is_null() {
                deps_normal.insert(dn.clone());
            }
            deps_all.insert(dn);
        }
        m.insert(
            name,
            Package {
                dir: manifest.parent().unwrap().to_path_buf(),
                deps_all,
                deps_normal,
            },
        );
    }
    m
}

/// Normal dependencies of `name` inside the workspace, transitively.
fn closure(ws: &BTreeMap<String, Package>, name: &str) -> BTreeSet<String> {
    let mut seen = BTreeSet::new();
    let mut todo = vec![name.to_string()];
    while let Some(n) = todo.pop() {
        if let Some(p) = ws.get(&n) {
            for d in &p.deps_normal {
                if ws.contains_key(d) && seen.insert(d.clone()) {
                    todo.push(d.clone());
                }
            }
        }
    }
    seen
}

#[test]
fn pack_depends_on_field_optics_common_only() {
    let ws = workspace();
    let deps = closure(&ws, "sunbeam-pack");
    let allowed: BTreeSet<String> = ["sunbeam-common", "sunbeam-field", "sunbeam-optics"]
        .map(String::from)
        .into();
    let extra: Vec<_> = deps.difference(&allowed).collect();
    assert!(
        extra.is_empty(),
        "sunbeam-pack (the physics core) depends on {extra:?}: it may depend on {allowed:?} only \
         (readers belong to sunbeam-afm, the scene's reach to sunbeam-scene, called by the tools)"
    );
}

#[test]
fn nothing_depends_on_a_tool() {
    let ws = workspace();
    let tools: BTreeSet<&String> = ws
        .iter()
        .filter(|(_, p)| p.dir.parent().is_some_and(|d| d.ends_with("tools")))
        .map(|(n, _)| n)
        .collect();
    assert!(!tools.is_empty(), "no tools found under tools/");
    let mut bad = vec![];
    for (n, p) in &ws {
        for d in &p.deps_all {
            if tools.contains(d) {
                bad.push(format!("{n} -> {d}"));
            }
        }
    }
    assert!(bad.is_empty(), "crates depend on tools: {bad:?}");
}

/// The `.rs` files of a top module `src/NAME.rs` or `src/NAME/` (with everything
/// under it, and `src/NAME.rs`'s own folder of submodules).
fn module_files(src: &Path, name: &str) -> Vec<PathBuf> {
    fn walk(d: &Path, out: &mut Vec<PathBuf>) {
        if let Ok(rd) = std::fs::read_dir(d) {
            let mut es: Vec<_> = rd.flatten().map(|e| e.path()).collect();
            es.sort();
            for p in es {
                if p.is_dir() {
                    walk(&p, out);
                } else if p.extension().is_some_and(|e| e == "rs") {
                    out.push(p);
                }
            }
        }
    }
    let mut out = vec![];
    let f = src.join(format!("{name}.rs"));
    if f.is_file() {
        out.push(f);
    }
    walk(&src.join(name), &mut out);
    out
}

/// Top modules of a crate's `src/`: `NAME.rs` and `NAME/` (not lib.rs, main.rs, bin/).
fn top_modules(src: &Path) -> BTreeSet<String> {
    let mut m = BTreeSet::new();
    if let Ok(rd) = std::fs::read_dir(src) {
        for e in rd.flatten() {
            let p = e.path();
            let stem = p.file_stem().unwrap().to_string_lossy().into_owned();
            let dir_module = p.is_dir() && stem != "bin";
            let file_module =
                p.extension().is_some_and(|x| x == "rs") && stem != "lib" && stem != "main";
            if dir_module || file_module {
                m.insert(stem);
            }
        }
    }
    m
}

/// Which top modules `text` refers to as `crate::NAME` (inside `use crate::{a, b::c}`
/// groups too). Unit tests (`#[cfg(test)]` to the end of the file) are skipped.
fn crate_refs(text: &str, modules: &BTreeSet<String>) -> BTreeSet<String> {
    let text = text.split("#[cfg(test)]").next().unwrap_or("");
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let mut refs = BTreeSet::new();
    for (i, _) in text.match_indices("crate::") {
        // Not `sunbeam_crate::` or `$crate::`.
        if text[..i]
            .chars()
            .next_back()
            .is_some_and(|c| c.is_alphanumeric() || c == '_' || c == '$')
        {
            continue;
        }
        let rest = &text[i + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let body = &group[..group.find('}').unwrap_or(group.len())];
            for item in body.split(',') {
                let n = ident(item.trim());
                if modules.contains(&n) {
                    refs.insert(n);
                }
            }
        } else {
            let n = ident(rest);
            if modules.contains(&n) {
                refs.insert(n);
            }
        }
    }
    refs
}

/// A cycle in `graph`, if any (as the list of its modules).
fn find_cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn dfs(
        n: &str,
        g: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(n.to_string(), 1);
        stack.push(n.to_string());
        for m in g.get(n).into_iter().flatten() {
            match state.get(m.as_str()).copied().unwrap_or(0) {
                1 => {
                    let at = stack.iter().position(|s| s == m).unwrap();
                    let mut c = stack[at..].to_vec();
                    c.push(m.clone());
                    return Some(c);
                }
                0 => {
                    if let Some(c) = dfs(m, g, state, stack) {
                        return Some(c);
                    }
                }
                _ => {}
            }
        }
        stack.pop();
        state.insert(n.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for n in graph.keys() {
        if state.get(n.as_str()).copied().unwrap_or(0) == 0 {
            let mut stack = vec![];
            if let Some(c) = dfs(n, graph, &mut state, &mut stack) {
                return Some(c);
            }
        }
    }
    None
}

#[test]
fn no_module_cycles_inside_a_crate() {
    let ws = workspace();
    let mut cycles = vec![];
    for (name, p) in &ws {
        let src = p.dir.join("src");
        let modules = top_modules(&src);
        let mut graph = BTreeMap::new();
        for m in &modules {
            let mut refs = BTreeSet::new();
            for f in module_files(&src, m) {
                let text = std::fs::read_to_string(&f).unwrap_or_default();
                refs.extend(crate_refs(&text, &modules));
            }
            refs.remove(m);
            graph.insert(m.clone(), refs);
        }
        if let Some(c) = find_cycle(&graph) {
            cycles.push(format!("{name}: {}", c.join(" -> ")));
        }
    }
    assert!(cycles.is_empty(), "module cycles: {cycles:?}");
}

#[test]
fn the_cycle_finder_finds_cycles() {
    let mods: BTreeSet<String> = ["a", "b", "c"].map(String::from).into();
    assert_eq!(
        crate_refs("use crate::{a, b::X};\nlet x = crate::c::f();", &mods),
        mods
    );
    assert!(crate_refs("use sunbeam_crate::a; $crate::b", &mods).is_empty());
    let g = |edges: &[(&str, &str)]| {
        let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for (a, b) in edges {
            g.entry(a.to_string()).or_default().insert(b.to_string());
            g.entry(b.to_string()).or_default();
        }
        g
    };
    assert!(find_cycle(&g(&[("a", "b"), ("b", "c")])).is_none());
    assert!(find_cycle(&g(&[("a", "b"), ("b", "c"), ("c", "a")])).is_some());
}

/// A tool's `main.rs` is its entry point, not its logic (docs/dev/ARCHITECTURE.md):
/// the command line goes in `args.rs`, the work in modules and crates.
#[test]
fn tool_mains_are_short() {
    const LIMIT: usize = 150;
    let mut long = Vec::new();
    for e in std::fs::read_dir(root().join("tools")).expect("tools/") {
        let main = e.expect("tools/ entry").path().join("src/main.rs");
        if let Ok(text) = std::fs::read_to_string(&main) {
            let n = text.lines().count();
            if n > LIMIT {
                long.push(format!("{} ({n} lines)", main.display()));
            }
        }
    }
    assert!(
        long.is_empty(),
        "tool main.rs files over {LIMIT} lines: {long:?}"
    );
}

/// Does `text` (Rust source, unit tests and `//` comments left out) start
/// threads by hand?
fn spawns_threads(text: &str) -> bool {
    let text = text.split("#[cfg(test)]").next().unwrap_or("");
    text.lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .any(|l| {
            ["thread::spawn", "thread::scope", "thread::Builder"]
                .iter()
                .any(|p| l.contains(p))
        })
}

/// Every `.rs` file under `dir`, sorted.
fn rs_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = vec![];
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        if let Ok(rd) = std::fs::read_dir(&d) {
            for p in rd.flatten().map(|e| e.path()) {
                if p.is_dir() {
                    stack.push(p);
                } else if p.extension().is_some_and(|e| e == "rs") {
                    out.push(p);
                }
            }
        }
    }
    out.sort();
    out
}

/// Parallel work goes through rayon, whose indexed collect keeps outputs in
/// order whatever the thread count (docs/dev/ARCHITECTURE.md): no crate or
/// tool starts threads of its own. Tests (`tests/`, `#[cfg(test)]`) may.
#[test]
fn no_hand_made_thread_pools() {
    let mut found = vec![];
    for p in workspace().values() {
        for f in rs_files(&p.dir.join("src")) {
            if spawns_threads(&std::fs::read_to_string(&f).unwrap_or_default()) {
                found.push(f.display().to_string());
            }
        }
    }
    assert!(found.is_empty(), "hand-made threads (use rayon): {found:?}");
}

#[test]
fn the_thread_finder_finds_threads() {
    assert!(spawns_threads(
        "fn f() {\n    std::thread::scope(|s| {\n        s.spawn(|| 1);\n    });\n}"
    ));
    assert!(spawns_threads("let h = thread::spawn(move || work());"));
    assert!(!spawns_threads(
        "// std::thread::spawn is not used here\nfn f() {}"
    ));
    assert!(!spawns_threads(
        "fn f() {}\n#[cfg(test)]\nmod tests { fn t() { std::thread::spawn(|| ()); } }"
    ));
    assert!(!spawns_threads(
        "let n = std::thread::available_parallelism();"
    ));
}
