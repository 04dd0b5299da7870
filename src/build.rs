//! Build script: record the git commit Shoal is built from (`SHOAL_GIT_COMMIT`), which the
//! review pack prints beside the version. Outside a git checkout (a crate tarball) it is
//! "unknown". Reruns when HEAD or the branch it points to moves.

use std::process::Command;

fn main() {
    let git = |args: &[&str]| {
        Command::new("git")
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .and_then(|o| String::from_utf8(o.stdout).ok())
            .map(|s| s.trim().to_string())
    };
    let commit = git(&["rev-parse", "--short=12", "HEAD"]).unwrap_or_else(|| "unknown".into());
    println!("cargo:rustc-env=SHOAL_GIT_COMMIT={commit}");
    // Watch only files that exist: a missing one would rerun this script on every build.
    if let Some(dir) = git(&["rev-parse", "--git-dir"]) {
        let reference = git(&["symbolic-ref", "-q", "HEAD"]).map(|r| format!("{dir}/{r}"));
        for path in [Some(format!("{dir}/HEAD")), reference, Some(format!("{dir}/packed-refs"))].into_iter().flatten() {
            if std::path::Path::new(&path).exists() {
                println!("cargo:rerun-if-changed={path}");
            }
        }
    }
    println!("cargo:rerun-if-changed=src/build.rs");
}
