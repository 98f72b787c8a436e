//! The shape of the workspace (docs/dev/ARCHITECTURE.md), checked so it stays:
//!
//! - the physics core `sunbeam-pack` depends on field, optics and common only
//!   (never on the instrument readers, the glTF loader or the render scene);
//! - no crate depends on a tool (a package under `tools/`);
//! - inside a crate, no cycle of `crate::` references between its top modules;
//! - every tool's `main.rs` stays under 150 lines;
//! - no hand-made thread pools (`std::thread::spawn`/`scope`/`Builder`) in the
//!   crates' and tools' sources: parallel work goes through rayon;
//! - the player (`sunbeam-render`) does not depend on the reference
//!   (`sunbeam-raster`) in any way, not even for its tests;
//! - no dev-dependency cycle: no crate's tests depend on a crate that depends
//!   on it;
//! - the crate graph of docs/dev/ARCHITECTURE.md is the workspace's, both ways.
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
/// normal dependency names, normal and build dependency names, dev-dependency names).
struct Package {
    dir: PathBuf,
    deps_all: BTreeSet<String>,
    deps_normal: BTreeSet<String>,
    deps_linked: BTreeSet<String>,
    deps_dev: BTreeSet<String>,
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
        let mut deps_linked = BTreeSet::new();
        let mut deps_dev = BTreeSet::new();
        for d in p["dependencies"].as_array().unwrap() {
            let dn = d["name"].as_str().unwrap().to_string();
            match d["kind"].as_str() {
                None => {
                    deps_normal.insert(dn.clone());
                    deps_linked.insert(dn.clone());
                }
                Some("build") => {
                    deps_linked.insert(dn.clone());
                }
                _ => {
                    deps_dev.insert(dn.clone());
                }
            }
            deps_all.insert(dn);
        }
        m.insert(
            name,
            Package {
                dir: manifest.parent().unwrap().to_path_buf(),
                deps_all,
                deps_normal,
                deps_linked,
                deps_dev,
            },
        );
    }
    m
}

/// Normal dependencies of `name` inside the workspace, transitively.
fn closure(ws: &BTreeMap<String, Package>, name: &str) -> BTreeSet<String> {
    closure_by(ws, name, |p| &p.deps_normal)
}

/// What `name` links inside the workspace (normal and build dependencies,
/// transitively): what `cargo tree -p NAME` shows without the dev-dependencies.
fn linked(ws: &BTreeMap<String, Package>, name: &str) -> BTreeSet<String> {
    closure_by(ws, name, |p| &p.deps_linked)
}

fn closure_by(
    ws: &BTreeMap<String, Package>,
    name: &str,
    deps: impl Fn(&Package) -> &BTreeSet<String>,
) -> BTreeSet<String> {
    let mut seen = BTreeSet::new();
    let mut todo = vec![name.to_string()];
    while let Some(n) = todo.pop() {
        if let Some(p) = ws.get(&n) {
            for d in deps(p) {
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

/// The player draws what the reference draws, but from the shared scene and
/// images (`sunbeam-frame`), never through the reference: `cargo tree -p
/// sunbeam-render` (its dev-dependencies included) has no `sunbeam-raster`.
/// The tests that compare the two live above both (the root package's tests/).
#[test]
fn the_player_does_not_depend_on_the_reference() {
    let ws = workspace();
    let render = ws.get("sunbeam-render").expect("sunbeam-render");
    let mut tree = linked(&ws, "sunbeam-render");
    for d in &render.deps_dev {
        tree.insert(d.clone());
        tree.extend(linked(&ws, d));
    }
    assert!(
        !tree.contains("sunbeam-raster"),
        "sunbeam-render depends on sunbeam-raster (through {:?})",
        render
            .deps_all
            .iter()
            .filter(|d| *d == "sunbeam-raster" || linked(&ws, d).contains("sunbeam-raster"))
            .collect::<Vec<_>>()
    );
}

/// The dev-dependency cycles of `ws`: `A` dev-depends on `B` while `B` links `A`.
fn dev_cycles(ws: &BTreeMap<String, Package>) -> Vec<String> {
    let mut bad = vec![];
    for (n, p) in ws {
        for d in &p.deps_dev {
            if ws.contains_key(d) && linked(ws, d).contains(n) {
                bad.push(format!("{n} dev-depends on {d}, which depends on {n}"));
            }
        }
    }
    bad
}

/// A crate's tests may use crates below it only: a test that needs a crate
/// above goes to that crate's tests (or the root package's).
#[test]
fn no_dev_dependency_cycle() {
    let bad = dev_cycles(&workspace());
    assert!(bad.is_empty(), "dev-dependency cycles: {bad:?}");
}

/// The crate graph of docs/dev/ARCHITECTURE.md ("The crate graph"): the lines
/// `NAME -> A, B, C   (external)` of its indented block, with continuation
/// lines; `tools/NAME` is the package in that folder. Parenthesised parts
/// (external crates, remarks) are left out. name -> workspace dependencies.
fn doc_graph(text: &str) -> BTreeMap<String, BTreeSet<String>> {
    let section = text
        .split("## The crate graph")
        .nth(1)
        .expect("a section \"## The crate graph\"");
    let section = section.split("\n## ").next().unwrap_or(section);
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut current: Option<String> = None;
    for line in section.lines() {
        if !line.starts_with("    ") {
            current = None;
            continue;
        }
        let mut plain = String::new();
        let mut depth = 0usize;
        for c in line.chars() {
            match c {
                '(' => depth += 1,
                ')' => depth = depth.saturating_sub(1),
                _ if depth == 0 => plain.push(c),
                _ => {}
            }
        }
        let deps = match plain.split_once("->") {
            Some((name, deps)) => {
                let name = name.trim().to_string();
                graph.entry(name.clone()).or_default();
                current = Some(name);
                deps.to_string()
            }
            None => plain,
        };
        let Some(name) = &current else { continue };
        let set = graph.get_mut(name).unwrap();
        set.extend(
            deps.split(',')
                .map(str::trim)
                .filter(|d| !d.is_empty())
                .map(String::from),
        );
    }
    graph
}

/// Where the doc's graph and the workspace's differ (`common` is left out of
/// both: "each crate also depends on `sunbeam-common`").
fn graph_drift(
    ws: &BTreeMap<String, Package>,
    doc: &BTreeMap<String, BTreeSet<String>>,
) -> Vec<String> {
    let common = "sunbeam-common";
    // The doc's names: `tools/NAME` for the packages under tools/, the package
    // name for the others; the root package (tests only) is not in the graph.
    let doc_name = |n: &str, p: &Package| -> String {
        match p.dir.parent() {
            Some(d) if d.ends_with("tools") => {
                format!("tools/{}", p.dir.file_name().unwrap().to_string_lossy())
            }
            _ => n.to_string(),
        }
    };
    let mut drift = vec![];
    let mut seen = BTreeSet::new();
    for (n, p) in ws {
        if p.dir == root() {
            continue;
        }
        let name = doc_name(n, p);
        seen.insert(name.clone());
        let meta: BTreeSet<String> = p
            .deps_normal
            .iter()
            .filter(|d| ws.contains_key(*d) && *d != common)
            .cloned()
            .collect();
        let Some(listed) = doc.get(&name) else {
            drift.push(format!("{name} is not in the graph"));
            continue;
        };
        let listed: BTreeSet<String> = listed.iter().filter(|d| *d != common).cloned().collect();
        let missing: Vec<_> = meta.difference(&listed).collect();
        let extra: Vec<_> = listed.difference(&meta).collect();
        if !missing.is_empty() {
            drift.push(format!("{name} also depends on {missing:?}"));
        }
        if !extra.is_empty() {
            drift.push(format!("{name} does not depend on {extra:?}"));
        }
    }
    for name in doc.keys() {
        if !seen.contains(name) {
            drift.push(format!("{name} is not a package of the workspace"));
        }
    }
    drift
}

/// docs/dev/ARCHITECTURE.md's crate graph is the workspace's (`cargo
/// metadata`'s normal dependencies), both ways: a dependency added or removed
/// in a Cargo.toml fails here until the doc says so.
#[test]
fn the_documented_crate_graph_is_the_workspace_graph() {
    let text = std::fs::read_to_string(root().join("docs/dev/ARCHITECTURE.md"))
        .expect("docs/dev/ARCHITECTURE.md");
    let drift = graph_drift(&workspace(), &doc_graph(&text));
    assert!(
        drift.is_empty(),
        "docs/dev/ARCHITECTURE.md's crate graph differs from Cargo.toml's: {drift:#?}"
    );
}

#[test]
fn the_graph_checks_find_drift() {
    let doc = doc_graph(
        "## The crate graph\n\ntext\n\n    tools/t -> a, b,\n               c   (ext, x)\n    \
         a -> (clap)\n    b -> a\n\nRules:\n\n## Next\n\n    z -> y\n",
    );
    let set = |v: &[&str]| -> BTreeSet<String> { v.iter().map(|s| s.to_string()).collect() };
    assert_eq!(doc["tools/t"], set(&["a", "b", "c"]));
    assert_eq!(doc["a"], set(&[]));
    assert_eq!(doc["b"], set(&["a"]));
    assert!(!doc.contains_key("z"));
    let pkg = |dir: &str, normal: &[&str], dev: &[&str]| Package {
        dir: PathBuf::from(dir),
        deps_all: set(normal).union(&set(dev)).cloned().collect(),
        deps_normal: set(normal),
        deps_linked: set(normal),
        deps_dev: set(dev),
    };
    let mut ws = BTreeMap::new();
    ws.insert("t-cli".to_string(), pkg("/w/tools/t", &["a", "b"], &[]));
    ws.insert("a".to_string(), pkg("/w/crates/a", &[], &["b"]));
    ws.insert("b".to_string(), pkg("/w/crates/b", &["a", "d"], &[]));
    ws.insert("d".to_string(), pkg("/w/crates/d", &[], &[]));
    assert_eq!(
        graph_drift(&ws, &doc),
        [
            "b also depends on [\"d\"]",
            "d is not in the graph",
            "tools/t does not depend on [\"c\"]",
        ]
    );
    let mut doc = doc;
    doc.insert("e".to_string(), BTreeSet::new());
    assert!(graph_drift(&ws, &doc).contains(&"e is not a package of the workspace".to_string()));
    assert_eq!(
        dev_cycles(&ws),
        vec!["a dev-depends on b, which depends on a"]
    );
}
