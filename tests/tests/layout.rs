//! The test layout: every package's integration tests are modules of its one test binary
//! (`autotests = false`), so a test file the binary does not name would never run. This checks
//! that each `.rs` file in a package's test directory is named by that binary's `#[path]`s.

use std::path::Path;

/// `(test directory, its test binary's file)` of every package, from the repository root.
const PACKAGE_TESTS: [(&str, &str); 5] = [
    ("sim/tests", "integration.rs"),
    ("scenes/tests", "integration.rs"),
    ("classifier/tests", "integration.rs"),
    ("tests/tests", "integration.rs"),
    ("tests", "cli.rs"),
];

#[test]
fn every_test_file_is_a_module_of_its_package_test_binary() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("tests/ sits in the repository");
    for (dir, binary) in PACKAGE_TESTS {
        let dir = root.join(dir);
        let main = std::fs::read_to_string(dir.join(binary)).expect("the test binary's file");
        let named: Vec<&str> =
            main.lines().filter_map(|l| l.trim().strip_prefix("#[path = \"")?.strip_suffix("\"]")).collect();
        let mut files = 0;
        for entry in std::fs::read_dir(&dir).expect("the test directory") {
            let name = entry.expect("an entry").file_name().to_string_lossy().into_owned();
            if name.ends_with(".rs") && name != binary {
                files += 1;
                assert!(named.contains(&name.as_str()), "{} is not a module of {binary}", dir.join(&name).display());
            }
        }
        assert!(files >= 5, "{}: {files} test files", dir.display());
    }
}
