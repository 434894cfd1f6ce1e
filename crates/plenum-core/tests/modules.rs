//! The module graph has no cycles (ARCHITECTURE.md): in plenum-core and plenum-spectrum no
//! top-level module uses, through any chain of `crate::` paths, a module that uses it back.
//! A cycle makes two concerns one, so neither can be read, tested or changed alone.
//!
//! The graph is read from the sources: a module is a file or folder under `src/`, its edges
//! the `crate::NAME` paths its code names (comments and `#[cfg(test)]` modules aside).

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

type Graph = BTreeMap<String, BTreeSet<String>>;

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).expect("a source folder") {
        let path = entry.expect("a folder entry").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The `crate::NAME`s a file's code names, tests and comments left out.
fn uses(source: &str) -> BTreeSet<String> {
    let code = source.split("#[cfg(test)]").next().unwrap_or("");
    let mut names = BTreeSet::new();
    for line in code.lines().map(|l| l.split("//").next().unwrap_or("")) {
        for (i, _) in line.match_indices("crate::") {
            let name: String = line[i + 7..]
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            if !name.is_empty() {
                names.insert(name);
            }
        }
    }
    names
}

fn module_graph(src: &Path) -> Graph {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let mut graph = Graph::new();
    for file in files {
        let relative = file.strip_prefix(src).expect("under src");
        let first = relative.components().next().expect("a path");
        let top = first
            .as_os_str()
            .to_string_lossy()
            .trim_end_matches(".rs")
            .to_string();
        if top == "lib" || top == "main" {
            continue;
        }
        let source = fs::read_to_string(&file).expect("a readable source file");
        let edges = graph.entry(top.clone()).or_default();
        edges.extend(uses(&source).into_iter().filter(|m| *m != top));
    }
    graph
}

/// A cycle of the graph, as the modules along it, if there is one (depth-first search).
fn find_cycle(graph: &Graph) -> Option<Vec<String>> {
    fn visit(
        node: &str,
        graph: &Graph,
        done: &mut BTreeSet<String>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        if let Some(at) = stack.iter().position(|n| n == node) {
            let mut cycle = stack[at..].to_vec();
            cycle.push(node.to_string());
            return Some(cycle);
        }
        if done.contains(node) {
            return None;
        }
        stack.push(node.to_string());
        for next in graph.get(node).into_iter().flatten() {
            if let Some(cycle) = visit(next, graph, done, stack) {
                return Some(cycle);
            }
        }
        stack.pop();
        done.insert(node.to_string());
        None
    }
    let mut done = BTreeSet::new();
    graph
        .keys()
        .find_map(|n| visit(n, graph, &mut done, &mut Vec::new()))
}

fn assert_acyclic(crate_dir: &str) {
    let src = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(crate_dir)
        .join("src");
    let graph = module_graph(&src);
    assert!(graph.len() > 5, "{}: the modules were found", src.display());
    if let Some(cycle) = find_cycle(&graph) {
        panic!(
            "{}: the modules {} form a cycle",
            src.display(),
            cycle.join(" → ")
        );
    }
}

#[test]
fn the_core_modules_form_no_cycle() {
    assert_acyclic(".");
}

#[test]
fn the_spectrum_modules_form_no_cycle() {
    assert_acyclic("../plenum-spectrum");
}

#[test]
fn a_cycle_is_found_and_named() {
    // The check itself: a → b → c → a is found, a tree is not.
    let mut graph = Graph::new();
    for (a, b) in [("a", "b"), ("b", "c"), ("c", "a"), ("c", "d")] {
        graph.entry(a.into()).or_default().insert(b.into());
    }
    let cycle = find_cycle(&graph).expect("a cycle");
    assert_eq!(cycle.first(), cycle.last());
    assert_eq!(cycle.len(), 4);
    graph.get_mut("c").unwrap().remove("a");
    assert_eq!(find_cycle(&graph), None);
    assert_eq!(
        uses("use crate::scene::Scene; // crate::render\n// crate::film\n#[cfg(test)]\nuse crate::x;"),
        BTreeSet::from(["scene".to_string()])
    );
}
