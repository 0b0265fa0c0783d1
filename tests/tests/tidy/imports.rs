//! File-level imports: which source file of a crate names which other (issue 52's cycle check).
//!
//! A file's module path comes from where it sits (`geom/src/pipeline/plan/parts.rs` is
//! `crate::pipeline::plan::parts`, a `mod.rs` is its folder). Every path in its code that starts with
//! `crate::`, `super::` or `self::` (in `use` statements, braces expanded, and inline) is
//! resolved to the longest module prefix that is a file: an edge from the file to that file.
//! Re-exports (`pub use`) only name things and make no edge; test modules (from the first
//! `#[cfg(test)]` on) are left out, since a test may use anything.

use std::collections::{BTreeMap, BTreeSet};

/// Per file of one crate (paths relative to the root, under `src`), the files it imports.
pub fn graph(src: &str, files: &[(String, String)]) -> BTreeMap<String, BTreeSet<String>> {
    let modules: BTreeMap<Vec<String>, String> =
        files.iter().filter_map(|(p, _)| Some((module_of(src, p)?, p.clone()))).collect();
    let mut out = BTreeMap::new();
    for (path, text) in files {
        let Some(me) = module_of(src, path) else { continue };
        let code = strip_comments(text.split("#[cfg(test)]").next().unwrap_or(""));
        let mut to = BTreeSet::new();
        for r in references(&code).into_iter().chain(child_references(&code)) {
            let Some(abs) = absolute(&me, &r) else { continue };
            // The longest prefix that is a module file.
            let target =
                (1..=abs.len()).rev().find_map(|k| modules.get(&abs[..k])).or_else(|| modules.get(&Vec::new()));
            if let Some(t) = target.filter(|t| *t != path) {
                to.insert(t.clone());
            }
        }
        out.insert(path.clone(), to);
    }
    out
}

/// The module path of a file under `src` (`None` for a binary's other roots).
fn module_of(src: &str, path: &str) -> Option<Vec<String>> {
    let rest = path.strip_prefix(src)?.strip_prefix('/')?;
    let rest = rest.strip_suffix(".rs")?;
    let mut segs: Vec<String> = rest.split('/').map(str::to_string).collect();
    if matches!(segs.last().map(String::as_str), Some("mod")) || segs == ["lib"] || segs == ["main"] {
        segs.pop();
    }
    Some(segs)
}

/// A reference made absolute from module `me`.
fn absolute(me: &[String], r: &[String]) -> Option<Vec<String>> {
    let mut base: Vec<String>;
    let mut rest = r;
    match r.first().map(String::as_str) {
        Some("crate") => {
            base = Vec::new();
            rest = &r[1..];
        }
        Some("self") => {
            base = me.to_vec();
            rest = &r[1..];
        }
        Some("super") => {
            base = me.to_vec();
            while rest.first().map(String::as_str) == Some("super") {
                base.pop()?;
                rest = &rest[1..];
            }
        }
        _ => return None,
    }
    base.extend(rest.iter().cloned());
    Some(base)
}

/// Code without `//` comments and string contents (roughly: enough for paths).
fn strip_comments(code: &str) -> String {
    code.lines().map(|l| l.split("//").next().unwrap_or("")).collect::<Vec<_>>().join("\n")
}

/// Every `crate::` / `super::` / `self::` path: `use` statements expanded, others inline.
fn references(code: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let mut rest = code;
    // `use` statements first (not `pub use`: a re-export only names).
    let mut inline = String::new();
    while let Some(i) = find_use(rest) {
        inline.push_str(&rest[..i.0]);
        let end = rest[i.1..].find(';').map_or(rest.len(), |e| i.1 + e);
        if !i.2 {
            expand(rest[i.1..end].trim(), &mut Vec::new(), &mut out);
        }
        rest = &rest[(end + 1).min(rest.len())..];
    }
    inline.push_str(rest);
    for start in ["crate::", "super::", "self::"] {
        out.extend(paths_from(&inline, start));
    }
    out
}

/// Paths into the file's own child modules (`mod x;` declared, `x::...` named), as
/// `self::x::...`; re-exports excepted.
fn child_references(code: &str) -> Vec<Vec<String>> {
    let children: Vec<&str> = code
        .lines()
        .filter_map(|l| {
            let t = l.trim();
            let t = t.strip_prefix("pub(crate) ").or_else(|| t.strip_prefix("pub ")).unwrap_or(t);
            t.strip_prefix("mod ")?.strip_suffix(';')
        })
        .collect();
    let code: String = code
        .lines()
        .filter(|l| {
            let t = l.trim_start();
            !(t.starts_with("pub use ")
                || t.starts_with("pub(crate) use ")
                || t.starts_with("mod ")
                || t.starts_with("pub mod "))
        })
        .collect::<Vec<_>>()
        .join("\n");
    let mut out = Vec::new();
    for c in children {
        let pat = format!("{c}::");
        out.extend(paths_from(&code, &pat).into_iter().map(|p| [vec!["self".to_string()], p].concat()));
        // `use x::{...}` and `use x;`
        let used =
            |t: &str| t.strip_prefix("use ").is_some_and(|r| r.starts_with(&pat) || r.starts_with(&format!("{c};")));
        if code.lines().any(|l| used(l.trim_start())) {
            out.push(vec!["self".to_string(), c.to_string()]);
        }
    }
    out
}

/// Every path in `code` that starts with `start` (not inside a longer path or name), split
/// at `::`.
fn paths_from(code: &str, start: &str) -> Vec<Vec<String>> {
    let b = code.as_bytes();
    let mut out = Vec::new();
    let mut from = 0;
    while let Some(k) = code[from..].find(start) {
        let at = from + k;
        from = at + start.len();
        if at > 0 && (b[at - 1].is_ascii_alphanumeric() || b[at - 1] == b'_' || b[at - 1] == b':') {
            continue;
        }
        let path: String = code[at..].chars().take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':').collect();
        out.push(path.split("::").filter(|s| !s.is_empty()).map(str::to_string).collect());
    }
    out
}

/// The next `use` statement: (where it starts, where its path starts, whether it is `pub`).
fn find_use(code: &str) -> Option<(usize, usize, bool)> {
    let mut from = 0;
    while let Some(k) = code[from..].find("use ") {
        let at = from + k;
        from = at + 4;
        let line_start = code[..at].rfind('\n').map_or(0, |n| n + 1);
        let before = code[line_start..at].trim();
        if before.is_empty() || before == "pub" || before.starts_with("pub(") {
            return Some((line_start, at + 4, !before.is_empty()));
        }
    }
    None
}

/// Expands `a::{b, c::{d, e}}` under `prefix` into whole paths.
fn expand(tree: &str, prefix: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
    let tree = tree.trim();
    match tree.find('{') {
        None => {
            let mut p = prefix.clone();
            let head = tree.split(" as ").next().unwrap_or(tree);
            p.extend(head.split("::").map(|s| s.trim().to_string()).filter(|s| !s.is_empty() && s != "*"));
            if p.last().is_some_and(|s| s == "self") {
                p.pop();
            }
            out.push(p);
        }
        Some(open) => {
            let head: Vec<String> =
                tree[..open].split("::").map(|s| s.trim().to_string()).filter(|s| !s.is_empty()).collect();
            let close = tree.rfind('}').unwrap_or(tree.len());
            let inner = &tree[open + 1..close];
            let n = prefix.len();
            prefix.extend(head);
            for part in split_top(inner) {
                expand(part, prefix, out);
            }
            prefix.truncate(n);
        }
    }
}

/// Splits at the commas outside braces.
fn split_top(s: &str) -> Vec<&str> {
    let (mut depth, mut start, mut out) = (0, 0, Vec::new());
    for (i, c) in s.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                out.push(&s[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    out.push(&s[start..]);
    out.into_iter().filter(|p| !p.trim().is_empty()).collect()
}

/// The strongly connected components with more than one file (Tarjan), each sorted.
pub fn cycles(g: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct T<'a> {
        g: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on: BTreeSet<&'a str>,
        out: Vec<Vec<String>>,
    }
    impl<'a> T<'a> {
        fn visit(&mut self, v: &'a str) {
            let i = self.index.len();
            self.index.insert(v, i);
            self.low.insert(v, i);
            self.stack.push(v);
            self.on.insert(v);
            for w in self.g.get(v).into_iter().flatten() {
                let w = w.as_str();
                if !self.g.contains_key(w) {
                    continue;
                }
                if !self.index.contains_key(w) {
                    self.visit(w);
                    let lw = self.low[w];
                    let lv = self.low.get_mut(v).expect("visited");
                    *lv = (*lv).min(lw);
                } else if self.on.contains(w) {
                    let iw = self.index[w];
                    let lv = self.low.get_mut(v).expect("visited");
                    *lv = (*lv).min(iw);
                }
            }
            if self.low[v] == self.index[v] {
                let mut scc = Vec::new();
                while let Some(w) = self.stack.pop() {
                    self.on.remove(w);
                    scc.push(w.to_string());
                    if w == v {
                        break;
                    }
                }
                if scc.len() > 1 {
                    scc.sort();
                    self.out.push(scc);
                }
            }
        }
    }
    let mut t =
        T { g, index: BTreeMap::new(), low: BTreeMap::new(), stack: Vec::new(), on: BTreeSet::new(), out: Vec::new() };
    for v in g.keys() {
        if !t.index.contains_key(v.as_str()) {
            t.visit(v);
        }
    }
    t.out.sort();
    t.out
}
