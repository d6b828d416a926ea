//! The layering of src/: data flows one way, case → model → kernels → assembly → driver. Each
//! top-level module of the library has a layer (`LAYERS`); a file may name (`crate::x` in code,
//! `porompm::x` in the binary) modules of its own layer or below, never one above. A file of a
//! module missing from the table fails the test until the module is given its place.
//!
//! Comments, string literals and `#[cfg(test)]` items are not read: a unit test is not part of
//! the program, and may build its input with a higher layer (a validated case, for example).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Every top-level module with its layer, lowest first.
const LAYERS: &[(&str, usize)] = &[
    // Foundations: no physics, no PETSc.
    ("algebra", 0),
    ("check", 0),
    ("layout", 0),
    ("scheme", 0),
    ("parallel", 0),
    ("progress", 0),
    ("plot", 0),
    // Regions read from files: a mesh's cells, a closed surface.
    ("geometry", 0),
    // The case file as data; the soil models, their parameters and their laws.
    ("case", 1),
    ("soils", 1),
    // The physical model: grid, materials, soil models, points, loads, boundaries.
    ("model", 2),
    ("analysis", 3),
    // The per-point kernels.
    ("kernels", 4),
    // The particle update, checkpoints' state, the points' distribution over ranks.
    ("update", 5),
    ("state", 5),
    ("distribution", 5),
    // Files; the global system (the only application module that talks to PETSc).
    ("io", 6),
    ("assembly", 6),
    // What a run measures and reports.
    ("verification", 7),
    ("diagnostics", 7),
    ("fields", 7),
    ("recorders", 7),
    ("summary", 7),
    // The algorithm; the checks of a case across its sections, which ask the model it builds and
    // the verification checks it names.
    ("driver", 8),
    ("validation", 8),
    // The commands.
    ("describe", 9),
    ("report", 9),
    ("sweep", 9),
    ("element_test", 9),
    ("main", 10),
];

/// The source with comments, string and character literals blanked (lengths kept).
fn code_of(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'/' && b.get(i + 1) == Some(&b'/') {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
            let mut depth = 0;
            while i < b.len() {
                if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
                    depth += 1;
                    i += 2;
                } else if b[i] == b'*' && b.get(i + 1) == Some(&b'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
        } else if b[i] == b'r' && (b.get(i + 1) == Some(&b'"') || b.get(i + 1) == Some(&b'#')) && !ident(b, i) {
            // A raw string r"..." or r#"..."#.
            let mut j = i + 1;
            let mut hashes = 0;
            while b.get(j) == Some(&b'#') {
                hashes += 1;
                j += 1;
            }
            if b.get(j) != Some(&b'"') {
                out.push('r');
                i += 1;
                continue;
            }
            j += 1;
            let close: Vec<u8> = std::iter::once(b'"').chain(std::iter::repeat_n(b'#', hashes)).collect();
            while j < b.len() && !b[j..].starts_with(&close) {
                j += 1;
            }
            i = j + close.len();
            out.push_str("\"\"");
        } else if b[i] == b'"' {
            i += 1;
            while i < b.len() && b[i] != b'"' {
                if b[i] == b'\\' {
                    i += 1;
                }
                i += 1;
            }
            i += 1;
            out.push_str("\"\"");
        } else if b[i] == b'\'' && is_char_literal(b, i) {
            i += 1;
            while i < b.len() && b[i] != b'\'' {
                if b[i] == b'\\' {
                    i += 1;
                }
                i += 1;
            }
            i += 1;
            out.push_str("' '");
        } else {
            let c = text[i..].chars().next().expect("in bounds");
            out.push(c);
            i += c.len_utf8();
        }
    }
    out
}

/// The code with every `#[cfg(test)]` item (up to its closing brace or semicolon) removed.
fn without_tests(code: &str) -> String {
    const MARK: &str = "#[cfg(test)]";
    let mut out = String::with_capacity(code.len());
    let mut rest = code;
    while let Some(at) = rest.find(MARK) {
        out.push_str(&rest[..at]);
        let item = &rest[at + MARK.len()..];
        let mut depth = 0usize;
        let mut end = item.len();
        for (i, c) in item.char_indices() {
            match c {
                '{' => depth += 1,
                '}' => {
                    depth = depth.saturating_sub(1);
                    if depth == 0 {
                        end = i + 1;
                        break;
                    }
                }
                ';' if depth == 0 => {
                    end = i + 1;
                    break;
                }
                _ => {}
            }
        }
        // Keep the line count, so that the lines named stay those of the file.
        out.extend(item[..end].chars().filter(|&c| c == '\n'));
        rest = &item[end..];
    }
    out.push_str(rest);
    out
}

/// Whether the byte before `i` continues an identifier (so `r` at `i` is not a raw-string prefix).
fn ident(b: &[u8], i: usize) -> bool {
    i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_')
}

/// Whether the quote at `i` opens a character literal rather than a lifetime (`'a`).
fn is_char_literal(b: &[u8], i: usize) -> bool {
    match (b.get(i + 1), b.get(i + 2)) {
        (Some(b'\\'), _) => true,
        (Some(_), Some(b'\'')) => true,
        // A multi-byte character: look for the closing quote within four bytes.
        (Some(c), _) if *c >= 0x80 => b[i + 1..(i + 6).min(b.len())].contains(&b'\''),
        _ => false,
    }
}

/// The top-level module a file of src/ belongs to.
fn module_of(path: &Path, src: &Path) -> Option<String> {
    let rel = path.strip_prefix(src).ok()?;
    let first = rel.components().next()?.as_os_str().to_str()?;
    let name = first.strip_suffix(".rs").unwrap_or(first);
    (name != "lib").then(|| name.to_string())
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("src/ is readable").flatten() {
        let p = entry.path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// The modules a file's code names (`crate::x`, or `porompm::x` in the binary), with a line each.
fn named_modules(code: &str, known: &BTreeMap<&str, usize>) -> Vec<(String, usize)> {
    let mut out = Vec::new();
    for (n, line) in code.lines().enumerate() {
        for prefix in ["crate::", "porompm::"] {
            let mut rest = line;
            while let Some(at) = rest.find(prefix) {
                let before = rest[..at].chars().last();
                let tail = &rest[at + prefix.len()..];
                let name: String = tail.chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
                if !before.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_') && known.contains_key(name.as_str()) {
                    out.push((name, n + 1));
                }
                rest = tail;
            }
        }
    }
    out
}

#[test]
fn no_module_names_a_module_of_a_higher_layer() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let layers: BTreeMap<&str, usize> = LAYERS.iter().copied().collect();
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    let mut wrong = Vec::new();
    let mut unknown = Vec::new();
    for f in &files {
        let Some(module) = module_of(f, &src) else { continue };
        let Some(&own) = layers.get(module.as_str()) else {
            unknown.push(f.display().to_string());
            continue;
        };
        let code = without_tests(&code_of(&std::fs::read_to_string(f).expect("a source file")));
        for (name, line) in named_modules(&code, &layers) {
            if layers[name.as_str()] > own {
                wrong.push(format!(
                    "{}:{line}: `{module}` (layer {own}) names `{name}` (layer {})",
                    f.strip_prefix(&src).unwrap_or(f).display(),
                    layers[name.as_str()]
                ));
            }
        }
    }
    assert!(unknown.is_empty(), "modules without a layer in tests/layers.rs: {unknown:?}");
    assert!(wrong.is_empty(), "imports from a higher layer:\n{}", wrong.join("\n"));
}

/// The scanner itself: comments and strings are not read, paths in code are.
#[test]
fn the_scanner_reads_code_and_skips_comments_and_strings() {
    let layers: BTreeMap<&str, usize> = LAYERS.iter().copied().collect();
    let code = code_of(
        "use crate::model::Model; // crate::driver\n/* crate::assembly */ let s = \"crate::driver\";\n\
         let r = r#\"crate::io\"#; let c = '\"'; fn f<'a>(x: &'a str) { crate::kernels::f(x) }\n",
    );
    let named: Vec<String> = named_modules(&code, &layers).into_iter().map(|(n, _)| n).collect();
    assert_eq!(named, ["model", "kernels"]);
}

/// Unit tests are skipped, the code after them is read with its line numbers kept.
#[test]
fn the_scanner_skips_unit_tests() {
    let layers: BTreeMap<&str, usize> = LAYERS.iter().copied().collect();
    let code = without_tests(&code_of(
        "use crate::model::Model;\n#[cfg(test)]\nuse crate::driver::run;\n#[cfg(test)]\nmod tests {\n    fn f() { crate::io::g() }\n}\nuse crate::kernels::f;\n",
    ));
    let named = named_modules(&code, &layers);
    assert_eq!(named, [("model".to_string(), 1), ("kernels".to_string(), 8)]);
}
