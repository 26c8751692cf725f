//! A line for whoever waits on `pip install -v ./python`: pip shows nothing
//! of a build but this and cargo's progress, so say what it costs.

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    if std::env::var("PROFILE").as_deref() == Ok("release") {
        println!(
            "cargo:warning=building softarm's Rust core in release mode, once: about 3 to 4 \
             minutes on 2 cores (3 min 16 s measured on a 2-core machine, numpy's download \
             included), less on more cores"
        );
    }
}
