//! The part of libtest's command line that a test file with its own harness (`harness = false`,
//! for the files that initialise PETSc once in their process) answers, so that `cargo test` and
//! `cargo nextest` run it alike: `--list` (with `--format terse`, and `--ignored` for the ignored
//! tests, of which these files have none), name filters, and `--exact`.

/// The tests the command line selects from `tests` (name, body), or `None` when it asked for the
/// list (printed here).
pub fn selected<T: Copy>(tests: &[(&'static str, T)]) -> Option<Vec<(&'static str, T)>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let flag = |f: &str| args.iter().any(|a| a == f);
    // Options that take a value: their value is not a filter.
    let valued = ["--format", "--test-threads", "--color", "--logfile", "--skip", "-Z"];
    let mut filters = Vec::new();
    let mut skips = Vec::new();
    let mut i = 0;
    while i < args.len() {
        let a = &args[i];
        if valued.contains(&a.as_str()) {
            if a == "--skip" {
                skips.extend(args.get(i + 1).cloned());
            }
            i += 2;
            continue;
        }
        if !a.starts_with('-') {
            filters.push(a.clone());
        }
        i += 1;
    }
    let exact = flag("--exact");
    let matches = |name: &str, f: &String| if exact { name == f } else { name.contains(f.as_str()) };
    let chosen: Vec<(&'static str, T)> = tests
        .iter()
        .filter(|_| flag("--include-ignored") || !flag("--ignored"))
        .filter(|(name, _)| filters.is_empty() || filters.iter().any(|f| matches(name, f)))
        .filter(|(name, _)| !skips.iter().any(|s| matches(name, s)))
        .copied()
        .collect();
    if flag("--list") {
        for (name, _) in &chosen {
            println!("{name}: test");
        }
        return None;
    }
    Some(chosen)
}

/// Runs `tests` one after the other through `call` (which returns a failure's message), each
/// holding the cores shared, prints libtest's lines and says whether all passed.
pub fn run<T: Copy>(tests: &[(&'static str, T)], call: impl Fn(T) -> Result<(), String>) -> bool {
    let mut failed = Vec::new();
    for &(name, body) in tests {
        let outcome = {
            let _cores = super::Cores::shared();
            call(body)
        };
        match outcome {
            Ok(()) => println!("test {name} ... ok"),
            Err(msg) => {
                println!("test {name} ... FAILED\n{msg}");
                failed.push(name);
            }
        }
    }
    let passed = tests.len() - failed.len();
    if failed.is_empty() {
        println!("\ntest result: ok. {passed} passed; 0 failed");
    } else {
        println!("\ntest result: FAILED. {passed} passed; {} failed: {failed:?}", failed.len());
    }
    failed.is_empty()
}
