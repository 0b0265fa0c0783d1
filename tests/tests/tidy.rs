//! Tidy: the repository's structure checks, as rust-analyzer's `tidy` test does (issue 52).
//!
//! Fails on: a Rust source file over [`MAX_FILE_LINES`] lines or a function over
//! [`MAX_FN_LINES`] lines that is not on its allow-list; a tolerance literal (`1e-9`, ...)
//! outside `geom/src/tol.rs` beyond a file's allowance; a file-level import cycle in any crate
//! that is not on its list ([`imports`]); ARCHITECTURE.md over 32 KiB or naming a path that does
//! not exist. The allow-lists record what exists today and may only shrink: an
//! entry that is no longer needed (the file or function got small, a literal moved into
//! `tol.rs`) fails the test too, so that whoever fixed it also removes the entry.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

const MAX_FILE_LINES: usize = 600;
const MAX_FN_LINES: usize = 120;
const MAX_ARCHITECTURE_BYTES: usize = 32 * 1024;

/// Files allowed over [`MAX_FILE_LINES`], with their lines today (they may not grow).
const LONG_FILES: &[(&str, usize)] = &[("geom/src/domain/tracer.rs", 641), ("geom/src/homology/basis.rs", 719)];

/// Functions allowed over [`MAX_FN_LINES`] (`file::name`), with their lines today.
const LONG_FNS: &[(&str, usize)] = &include!("tidy_long_fns.in");

/// Tolerance literals allowed outside `tol.rs`, per file, with their count today.
const TOLERANCES: &[(&str, usize)] = &include!("tidy_tolerances.in");

/// The crates whose sources are checked.
const CRATES: &[&str] = &["geom", "server", "worker", "store", "cli", "proto", "tests"];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("the workspace root").to_path_buf()
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// Every checked source file, as (path relative to the root, text).
fn sources() -> Vec<(String, String)> {
    let root = root();
    let mut files = Vec::new();
    for c in CRATES {
        for sub in ["src", "tests", "examples", "benches"] {
            rust_files(&root.join(c).join(sub), &mut files);
        }
    }
    files.sort();
    files
        .into_iter()
        .map(|p| {
            let rel = p.strip_prefix(&root).expect("under the root").to_string_lossy().replace('\\', "/");
            let text = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{rel}: {e}"));
            (rel, text)
        })
        .collect()
}

/// Function names and their lengths in lines: from the `fn` line to the closing brace at the
/// same indentation (rustfmt's layout); declarations without a body are skipped.
fn functions(text: &str) -> Vec<(String, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let trimmed = line.trim_start();
        let indent = line.len() - trimmed.len();
        let Some(at) = fn_name_start(trimmed) else { continue };
        let name: String = trimmed[at..].chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
        // The signature ends at the first line ending in `{` (a body) or `;` (none).
        let Some(open) = (i..lines.len()).find(|&k| {
            let t = lines[k].trim_end();
            t.ends_with('{') || t.ends_with(';') || t.ends_with('}')
        }) else {
            continue;
        };
        let t = lines[open].trim_end();
        if t.ends_with(';') || t.ends_with('}') {
            continue;
        }
        let close = format!("{}}}", " ".repeat(indent));
        if let Some(end) = (open + 1..lines.len()).find(|&k| lines[k].trim_end() == close) {
            out.push((name, end - i + 1));
        }
    }
    out
}

/// Where the name starts in a line that declares a function (after `pub`, `async`, ...).
fn fn_name_start(line: &str) -> Option<usize> {
    let mut rest = line;
    let mut offset = 0;
    loop {
        let word = ["pub(crate) ", "pub(super) ", "pub ", "async ", "const ", "unsafe ", "extern \"C\" "]
            .into_iter()
            .find(|w| rest.starts_with(w));
        match word {
            Some(w) => {
                rest = &rest[w.len()..];
                offset += w.len();
            }
            None => break,
        }
    }
    rest.starts_with("fn ").then_some(offset + 3)
}

/// Scientific literals below one (`1e-9`, `2.5e-4`) in code, outside comments.
fn tolerance_literals(text: &str) -> usize {
    text.lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .map(|code| {
            let b = code.as_bytes();
            (0..b.len())
                .filter(|&i| {
                    b[i] == b'e'
                        && b.get(i + 1) == Some(&b'-')
                        && b.get(i + 2).is_some_and(u8::is_ascii_digit)
                        && i > 0
                        && b[i - 1].is_ascii_digit()
                        && (i < 2 || !(b[i - 2].is_ascii_alphabetic() || b[i - 2] == b'_') || b[i - 2] == b'.')
                })
                .count()
        })
        .sum()
}

/// Compares what is found against an allow-list that may only shrink.
fn against(what: &str, limit: &str, found: &BTreeMap<String, usize>, allowed: &[(&str, usize)]) -> Vec<String> {
    let allowed: BTreeMap<&str, usize> = allowed.iter().copied().collect();
    let mut errors = Vec::new();
    for (k, &n) in found {
        match allowed.get(k.as_str()) {
            None => errors.push(format!("{what} {k}: {n} (over {limit}; make it smaller)")),
            Some(&a) if n > a => errors.push(format!("{what} {k}: {n}, more than the {a} allowed; make it smaller")),
            Some(&a) if n < a => errors.push(format!("{what} {k}: {n}, fewer than {a}: lower its allow-list entry")),
            _ => {}
        }
    }
    for k in allowed.keys() {
        if !found.contains_key(*k) {
            errors.push(format!("{what} {k} is allowed but no longer needs it: remove its allow-list entry"));
        }
    }
    errors
}

#[test]
fn files_functions_and_tolerances_stay_within_their_limits() {
    let mut files = BTreeMap::new();
    let mut fns = BTreeMap::new();
    let mut tolerances = BTreeMap::new();
    for (path, text) in sources() {
        let n = text.lines().count();
        if n > MAX_FILE_LINES {
            files.insert(path.clone(), n);
        }
        for (name, len) in functions(&text) {
            if len > MAX_FN_LINES {
                let key = format!("{path}::{name}");
                let e = fns.entry(key).or_insert(0);
                *e = len.max(*e);
            }
        }
        if path.starts_with("geom/src/") && path != "geom/src/tol.rs" {
            let k = tolerance_literals(&text);
            if k > 0 {
                tolerances.insert(path, k);
            }
        }
    }
    let mut errors = against("file", &format!("{MAX_FILE_LINES} lines"), &files, LONG_FILES);
    errors.extend(against("function", &format!("{MAX_FN_LINES} lines"), &fns, LONG_FNS));
    errors.extend(against("tolerance literals in", "0: name it in geom/src/tol.rs", &tolerances, TOLERANCES));
    assert!(errors.is_empty(), "tidy:\n{}", errors.join("\n"));
}

#[test]
fn architecture_md_is_a_map_of_paths_that_exist() {
    let root = root();
    let text = std::fs::read_to_string(root.join("ARCHITECTURE.md")).expect("ARCHITECTURE.md");
    assert!(text.len() <= MAX_ARCHITECTURE_BYTES, "ARCHITECTURE.md is {} bytes, over 32 KiB", text.len());
    // A path in backticks is resolved from the root, a crate, or a folder the map describes.
    let bases = [
        "",
        "geom/src",
        "geom/src/crossparam",
        "geom/src/pipeline",
        "geom/src/domain",
        "geom/src/homology",
        "server",
        "server/src",
        "worker/src",
        "store/src",
        "cli/src",
        "proto",
    ];
    let missing: Vec<&str> = text
        .split('`')
        .skip(1)
        .step_by(2)
        .filter(|p| p.contains('/') && !p.starts_with('/') && !p.contains(' '))
        .filter(|p| p.chars().all(|c| c.is_alphanumeric() || "_./-".contains(c)))
        .filter(|p| !bases.iter().any(|b| root.join(b).join(p).exists()))
        .collect();
    assert!(missing.is_empty(), "ARCHITECTURE.md names paths that do not exist: {missing:?}");
}

#[test]
fn the_checks_catch_what_they_are_for() {
    let long = format!("fn big() {{\n{}}}\n", "    let x = 1;\n".repeat(MAX_FN_LINES));
    assert_eq!(functions(&long), vec![("big".to_string(), MAX_FN_LINES + 2)]);
    assert!(functions("pub trait T {\n    fn f(&self);\n}\n").is_empty());
    assert_eq!(tolerance_literals("let t = 1e-9; // 1e-3 in a comment\nlet u = 2.5e-4 * x1e-3;"), 2);
    let found = BTreeMap::from([("a".to_string(), 3)]);
    assert!(against("file", "x", &found, &[("a", 3)]).is_empty());
    assert_eq!(against("file", "x", &found, &[("a", 4)]).len(), 1, "a shrunk entry must be lowered");
    assert_eq!(against("file", "x", &found, &[]).len(), 1, "a new violation fails");
    assert_eq!(against("file", "x", &BTreeMap::new(), &[("a", 3)]).len(), 1, "a stale entry fails");
}

#[path = "tidy/imports.rs"]
mod imports;

/// File-level import cycles that exist today (each the sorted files of one strongly connected
/// component of a crate's import graph, [`imports`]); the list may only shrink.
const CYCLES: &[&str] = &[];

/// Every file-level import cycle of every crate.
fn all_cycles(files: &[(String, String)]) -> Vec<String> {
    let mut out = Vec::new();
    for c in CRATES {
        let src = format!("{c}/src");
        let own: Vec<(String, String)> =
            files.iter().filter(|(p, _)| p.starts_with(&format!("{src}/"))).cloned().collect();
        out.extend(imports::cycles(&imports::graph(&src, &own)).into_iter().map(|c| c.join(" ")));
    }
    out
}

#[test]
fn no_new_import_cycle() {
    let found: BTreeMap<String, usize> = all_cycles(&sources()).into_iter().map(|c| (c, 1)).collect();
    let allowed: Vec<(&str, usize)> = CYCLES.iter().map(|c| (*c, 1)).collect();
    let errors = against("import cycle", "none: import downward", &found, &allowed);
    assert!(errors.is_empty(), "tidy:\n{}", errors.join("\n"));
}

#[test]
fn the_cycle_check_sees_sibling_parent_and_child_imports() {
    let files = |a: &str, b: &str, m: &str| {
        vec![
            ("x/src/lib.rs".to_string(), "mod p;\n".to_string()),
            ("x/src/p/mod.rs".to_string(), format!("mod a;\nmod b;\n{m}")),
            ("x/src/p/a.rs".to_string(), a.to_string()),
            ("x/src/p/b.rs".to_string(), b.to_string()),
        ]
    };
    let cyc = |f: Vec<(String, String)>| imports::cycles(&imports::graph("x/src", &f));
    // Siblings, braces expanded.
    let f = files("use super::{b::B, c};\n", "fn g() { crate::p::a::f(); }\n", "");
    assert_eq!(cyc(f), vec![vec!["x/src/p/a.rs".to_string(), "x/src/p/b.rs".to_string()]]);
    // A child naming its parent's item while the parent calls the child.
    let f = files("use super::Item;\n", "", "pub struct Item;\nfn h() { a::f(); }\n");
    assert_eq!(cyc(f).len(), 1);
    // Re-exports, comments and tests make no edge.
    let f = files(
        "use super::Item;\n// b::x\n#[cfg(test)]\nuse super::b::T;\n",
        "use super::a::A;\n",
        "pub use a::A;\npub struct Item;\n",
    );
    assert!(cyc(f).is_empty());
}

/// The folder of each pipeline method (one job kind each, `homology` with its feature jobs).
const METHOD_DIRS: &[&str] = &[
    "geom/src/pipeline/layout/",
    "geom/src/pipeline/homology/",
    "geom/src/pipeline/quad/",
    "geom/src/pipeline/spherical/",
];

/// What a method folder may import of `pipeline` besides its own files.
const METHOD_MAY_IMPORT: &[&str] = &["geom/src/pipeline/common/", "geom/src/pipeline/spec/"];

/// The three phases in order; each imports only earlier ones (and the methods, `common`,
/// `spec` and `report.rs`), never a later one.
const PHASES: &[&str] = &["geom/src/pipeline/plan/", "geom/src/pipeline/run/", "geom/src/pipeline/finish/"];

#[test]
fn pipeline_methods_and_phases_import_downward() {
    let files: Vec<(String, String)> = sources().into_iter().filter(|(p, _)| p.starts_with("geom/src/")).collect();
    let g = imports::graph("geom/src", &files);
    let mut errors = Vec::new();
    for (from, to) in g.iter().flat_map(|(f, ts)| ts.iter().map(move |t| (f, t))) {
        if let Some(m) = METHOD_DIRS.iter().find(|d| from.starts_with(**d)) {
            let ok = to.starts_with(*m)
                || !to.starts_with("geom/src/pipeline/")
                || METHOD_MAY_IMPORT.iter().any(|d| to.starts_with(*d));
            if !ok {
                errors.push(format!("method file {from} imports {to}"));
            }
        }
        let phase = |p: &str| PHASES.iter().position(|d| p.starts_with(*d));
        if let (Some(a), Some(b)) = (phase(from), phase(to))
            && b > a
        {
            errors.push(format!("phase file {from} imports the later phase's {to}"));
        }
    }
    assert!(errors.is_empty(), "the pipeline imports upward:\n{}", errors.join("\n"));
}

/// `mesh` is the ground floor of `geom`: its files import only each other, `error` and `tol`.
#[test]
fn the_mesh_model_imports_nothing_above_it() {
    let files: Vec<(String, String)> = sources().into_iter().filter(|(p, _)| p.starts_with("geom/src/")).collect();
    let g = imports::graph("geom/src", &files);
    let below = ["geom/src/error.rs", "geom/src/tol.rs", "geom/src/lib.rs"];
    let errors: Vec<String> = g
        .iter()
        .filter(|(f, _)| f.starts_with("geom/src/mesh/"))
        .flat_map(|(f, ts)| {
            ts.iter()
                .filter(|t| !t.starts_with("geom/src/mesh/") && !below.contains(&t.as_str()))
                .map(move |t| format!("{f} imports {t}"))
        })
        .collect();
    assert!(errors.is_empty(), "the mesh model imports upward:\n{}", errors.join("\n"));
}

/// `geom`'s top-level modules (`mesh`, `topology`, ..., `pipeline`) import each other as a DAG:
/// the file graph collapsed to modules has no cycle.
#[test]
fn geom_modules_form_a_dag() {
    let files: Vec<(String, String)> = sources().into_iter().filter(|(p, _)| p.starts_with("geom/src/")).collect();
    let module = |p: &str| {
        let rest = &p["geom/src/".len()..];
        rest.split('/').next().unwrap_or(rest).trim_end_matches(".rs").to_string()
    };
    let mut modules: BTreeMap<String, std::collections::BTreeSet<String>> = BTreeMap::new();
    for (from, to) in imports::graph("geom/src", &files) {
        let a = module(&from);
        let set = modules.entry(a.clone()).or_default();
        set.extend(to.iter().map(|t| module(t)).filter(|b| *b != a && b != "lib"));
    }
    let cyc = imports::cycles(&modules);
    assert!(cyc.is_empty(), "geom modules import each other in a circle: {cyc:?}");
}
