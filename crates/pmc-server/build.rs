//! Stages the web viewer for embedding: copies `viewer/dist` (the output of `npm run build` in
//! `viewer/`) to `$OUT_DIR/viewer`, or writes a placeholder page there when the viewer has not
//! been built, so the crate always compiles.

use std::fs;
use std::io;
use std::path::{Path, PathBuf};

const FALLBACK: &str = r#"<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>PMC viewer not built</title>
<style>body{font:16px/1.5 system-ui,sans-serif;max-width:40em;margin:4em auto;padding:0 1em}code{background:#eee;padding:0 .3em}</style>
</head>
<body>
<h1>The PMC viewer is not built</h1>
<p>This <code>pmc</code> binary was compiled before the web viewer was built, so it has no viewer
to serve. The HTTP API works: try <a href="/api/v1/planet">/api/v1/planet</a>.</p>
<p>To get the viewer, run <code>./scripts/run.sh</code> from the repository root (it builds the
viewer and then <code>pmc</code>), or build it by hand: <code>cd viewer &amp;&amp; npm ci &amp;&amp;
npm run build</code>, then rebuild <code>pmc</code> (<code>cargo build --release --bin pmc</code>).</p>
</body>
</html>
"#;

fn copy_dir(from: &Path, to: &Path) -> io::Result<()> {
    fs::create_dir_all(to)?;
    for entry in fs::read_dir(from)? {
        let entry = entry?;
        let kind = entry.file_type()?;
        let target = to.join(entry.file_name());
        if kind.is_dir() {
            copy_dir(&entry.path(), &target)?;
        } else if kind.is_file() {
            fs::copy(entry.path(), &target)?;
        }
        // Symbolic links and other special files are not part of a viewer build: skipped.
    }
    Ok(())
}

fn main() -> io::Result<()> {
    let manifest = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR")).join("viewer");
    let viewer = manifest.join("../../viewer");
    let dist = viewer.join("dist");
    if out.exists() {
        fs::remove_dir_all(&out)?;
    }
    if dist.join("index.html").is_file() {
        copy_dir(&dist, &out)?;
        println!("cargo:rustc-env=PMC_VIEWER_BUILT=1");
        println!("cargo:rerun-if-changed={}", dist.display());
        println!("cargo:rerun-if-changed={}", dist.join("index.html").display());
    } else {
        fs::create_dir_all(&out)?;
        fs::write(out.join("index.html"), FALLBACK)?;
        println!("cargo:rustc-env=PMC_VIEWER_BUILT=0");
        println!(
            "cargo:warning=viewer/dist is missing: `pmc serve` will show a placeholder page (build the viewer with ./scripts/run.sh)"
        );
        // Watch the viewer folder (when there is one) so that building it later is noticed; a
        // missing path would instead rerun this script on every build.
        if viewer.is_dir() {
            println!("cargo:rerun-if-changed={}", viewer.display());
        } else {
            println!("cargo:rerun-if-changed={}", dist.display());
        }
    }
    println!("cargo:rerun-if-changed=build.rs");
    Ok(())
}
