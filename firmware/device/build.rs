//! Links the device binary and its examples with cortex-m-rt's `link.x` (which includes the top-level
//! `memory.x`) when building for a Cortex-M target; host builds are untouched.

fn main() {
    let target = std::env::var("TARGET").unwrap_or_default();
    if target.starts_with("thumb") {
        for kind in ["bins", "examples"] {
            println!("cargo:rustc-link-arg-{kind}=-Tlink.x");
            if std::env::var_os("CARGO_FEATURE_DEFMT").is_some() {
                println!("cargo:rustc-link-arg-{kind}=-Tdefmt.x");
            }
        }
    }
    println!("cargo:rerun-if-changed=../../memory.x");
    println!("cargo:rerun-if-changed=build.rs");
}
