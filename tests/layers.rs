//! The folders of `src/` are layers (docs/architecture.md): a module may use its own layer and
//! the layers below it, never one above. This reads every source file and fails on a `crate::`
//! path that points up, naming the file and line, and on a source file or function that has
//! grown past the size the team keeps to.

use std::path::{Path, PathBuf};

/// Bottom to top. `models/` (the model files) sits with `model`, the interface it implements.
const LAYERS: [&str; 9] = [
    "model", "engine", "input", "parallel", "voids", "output", "solve", "driver", "lab",
];

fn rank(layer: &str) -> Option<usize> {
    match layer {
        "models" | "pairs" => Some(0),
        _ => LAYERS.iter().position(|l| *l == layer),
    }
}

fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            sources(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The layer a file belongs to: its folder under `src/`, or `models`.
fn layer_of(root: &Path, file: &Path) -> Option<String> {
    let rel = file.strip_prefix(root).unwrap();
    let parts: Vec<_> = rel
        .iter()
        .map(|c| c.to_string_lossy().to_string())
        .collect();
    match parts.as_slice() {
        [top, ..] if top == "models" || top == "pairs" => Some(top.clone()),
        [src, layer, _, ..] if src == "src" => Some(layer.clone()),
        _ => None, // lib.rs, main.rs: above every layer
    }
}

/// `crate::NAME` paths in code (comments dropped), with their line numbers; macros
/// (`crate::attributes!`) are exported at the crate root and are not paths into a layer.
fn crate_paths(text: &str) -> Vec<(usize, String)> {
    let mut found = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let code = line.split("//").next().unwrap_or("");
        let mut rest = code;
        while let Some(k) = rest.find("crate::") {
            let after = &rest[k + 7..];
            let name: String = after
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            let is_macro = after[name.len()..].starts_with('!');
            if !name.is_empty() && !is_macro {
                found.push((n + 1, name));
            }
            rest = after;
        }
    }
    found
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn all_sources() -> Vec<PathBuf> {
    let root = root();
    let mut files = Vec::new();
    sources(&root.join("src"), &mut files);
    sources(&root.join("models"), &mut files);
    sources(&root.join("pairs"), &mut files);
    files.sort();
    files
}

#[test]
fn no_module_uses_a_layer_above_its_own() {
    let root = root();
    let mut up = Vec::new();
    for file in all_sources() {
        let Some(layer) = layer_of(&root, &file) else {
            continue;
        };
        let own = rank(&layer).unwrap_or_else(|| panic!("{} is in no layer", file.display()));
        let text = std::fs::read_to_string(&file).unwrap();
        for (line, name) in crate_paths(&text) {
            if (layer == "models" || layer == "pairs") && name != "model" && name != "models" {
                up.push(format!(
                    "{}:{line}: a model file uses crate::{name} (models see only crate::model)",
                    file.display()
                ));
            }
            if let Some(r) = rank(&name) {
                if r > own {
                    up.push(format!(
                        "{}:{line}: layer '{layer}' uses crate::{name}, a layer above it",
                        file.display()
                    ));
                }
            }
        }
    }
    assert!(up.is_empty(), "imports that point up:\n{}", up.join("\n"));
}

#[test]
fn every_layer_folder_is_known() {
    for e in std::fs::read_dir(root().join("src")).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            assert!(
                rank(&name).is_some(),
                "src/{name}/ is not in the layer list of tests/layers.rs (and docs/architecture.md)"
            );
        }
    }
}

/// The lengths the team keeps to (issue 22): a source file of about 700 lines, a function
/// of about 120, test modules included in the file but not counted as functions.
const FILE_LINES: usize = 720;
const FUNCTION_LINES: usize = 125;

/// Lines of each `fn` outside `#[cfg(test)]` modules, found by brace depth from its header.
fn long_functions(text: &str) -> Vec<(usize, usize, String)> {
    let lines: Vec<&str> = text.lines().collect();
    let end = lines
        .iter()
        .position(|l| l.trim_start() == "#[cfg(test)]")
        .unwrap_or(lines.len());
    let mut out = Vec::new();
    let mut n = 0;
    while n < end {
        let t = lines[n].trim_start();
        let is_fn =
            (t.starts_with("fn ") || t.starts_with("pub fn ") || t.starts_with("pub(crate) fn "))
                || (t.starts_with("pub(super) fn ") || t.starts_with("const fn "));
        if is_fn {
            let name: String = t
                .split("fn ")
                .nth(1)
                .unwrap_or("")
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            let (mut depth, mut opened, mut k) = (0i64, false, n);
            while k < lines.len() {
                let code = lines[k].split("//").next().unwrap_or("");
                for c in code.chars() {
                    match c {
                        '{' => {
                            depth += 1;
                            opened = true;
                        }
                        '}' => depth -= 1,
                        _ => {}
                    }
                }
                if opened && depth <= 0 {
                    break;
                }
                if !opened && code.trim_end().ends_with(';') {
                    break; // a declaration in a trait
                }
                k += 1;
            }
            let len = k - n + 1;
            if len > FUNCTION_LINES {
                out.push((n + 1, len, name));
            }
        }
        n += 1;
    }
    out
}

/// What is still over those sizes, at most as long as it is now (tightened as items shrink):
/// (file under the crate root, function or "" for the file itself, lines). Splitting one
/// removes it from here; the test fails if one grows, if a new one appears, or if a listed
/// one has been brought within the limit and is still listed.
const STILL_LONG: &[(&str, &str, usize)] = &[];

#[test]
fn files_and_functions_stay_readable() {
    let root = root();
    let mut found = Vec::new();
    for file in all_sources() {
        let rel = file
            .strip_prefix(&root)
            .unwrap()
            .to_string_lossy()
            .to_string();
        let text = std::fs::read_to_string(&file).unwrap();
        let lines = text.lines().count();
        if lines > FILE_LINES {
            found.push((rel.clone(), String::new(), lines));
        }
        for (_, len, name) in long_functions(&text) {
            found.push((rel.clone(), name, len));
        }
    }
    let mut wrong = Vec::new();
    for (file, name, len) in &found {
        let what = if name.is_empty() {
            String::new()
        } else {
            format!(" fn {name}")
        };
        match STILL_LONG.iter().find(|(f, n, _)| f == file && n == name) {
            None => wrong.push(format!("{file}{what}: {len} lines (split it)")),
            Some(&(_, _, was)) if *len > was => wrong.push(format!(
                "{file}{what}: {len} lines, was {was} (split it, don't grow it)"
            )),
            Some(_) => {}
        }
    }
    for (file, name, _) in STILL_LONG {
        if !found.iter().any(|(f, n, _)| f == file && n == name) {
            wrong.push(format!(
                "{file} {name}: within the limit now; remove it from STILL_LONG"
            ));
        }
    }
    assert!(wrong.is_empty(), "sizes:\n{}", wrong.join("\n"));
}
