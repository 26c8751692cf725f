//! `generated/` is committed and in sync, and the generator's cache works:
//! an unchanged model is neither re-derived nor rewritten.

use std::path::Path;

use crate::common::*;
use eomgen::generate::{SyncOptions, sync};

#[test]
fn generated_is_in_sync_with_models() {
    // Full re-derivation and byte comparison: also catches a generator
    // change made without bumping GENERATOR_VERSION.
    let opts = SyncOptions {
        force: true,
        check: true,
        absolute_paths: false,
    };
    let report = sync(&root().join("models"), &root().join("generated"), &opts).unwrap();
    assert!(
        report.is_clean(),
        "generated/ is stale: run `cargo run -- derive --force` and commit. Stale: {:?} {:?}",
        report.written,
        report.removed
    );
}

fn copy_models(to: &Path, names: &[&str]) {
    std::fs::create_dir_all(to).unwrap();
    for n in names {
        std::fs::copy(model_path(n), to.join(format!("{n}.toml"))).unwrap();
    }
}

fn snapshot(dir: &Path) -> Vec<(String, std::time::SystemTime, String)> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let p = e.unwrap().path();
            let meta = std::fs::metadata(&p).unwrap();
            (
                p.display().to_string(),
                meta.modified().unwrap(),
                std::fs::read_to_string(&p).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

#[test]
fn unchanged_models_are_not_rederived_or_rewritten() {
    let dir = tempfile::tempdir().unwrap();
    let (models, out) = (dir.path().join("models"), dir.path().join("generated"));
    copy_models(&models, &["double_pendulum", "chain"]);
    let first = sync(&models, &out, &SyncOptions::default()).unwrap();
    assert_eq!(first.derived, ["chain", "double_pendulum"]);
    assert_eq!(first.written.len(), 3); // two models and mod.rs
    let before = snapshot(&out);
    std::thread::sleep(std::time::Duration::from_millis(20));
    let second = sync(&models, &out, &SyncOptions::default()).unwrap();
    assert!(second.derived.is_empty(), "re-derived {:?}", second.derived);
    assert!(second.written.is_empty(), "rewrote {:?}", second.written);
    assert_eq!(snapshot(&out), before, "files touched");
}

#[test]
fn numeric_edit_reuses_structural_edit_rederives() {
    let dir = tempfile::tempdir().unwrap();
    let (models, out) = (dir.path().join("models"), dir.path().join("generated"));
    copy_models(&models, &["double_pendulum", "chain"]);
    sync(&models, &out, &SyncOptions::default()).unwrap();
    let chain = models.join("chain.toml");
    let text = std::fs::read_to_string(&chain).unwrap();
    std::fs::write(&chain, text.replace("mass = 0.4", "mass = 0.7")).unwrap();
    let numeric = sync(&models, &out, &SyncOptions::default()).unwrap();
    assert!(numeric.derived.is_empty() && numeric.written.is_empty());
    std::fs::write(&chain, text.replace("elements = 8", "elements = 4")).unwrap();
    let structural = sync(&models, &out, &SyncOptions::default()).unwrap();
    assert_eq!(structural.derived, ["chain"]);
    assert_eq!(structural.written, [out.join("chain.rs")]);
}

#[test]
fn removed_model_removes_its_generated_file() {
    let dir = tempfile::tempdir().unwrap();
    let (models, out) = (dir.path().join("models"), dir.path().join("generated"));
    copy_models(&models, &["double_pendulum", "chain"]);
    sync(&models, &out, &SyncOptions::default()).unwrap();
    std::fs::remove_file(models.join("chain.toml")).unwrap();
    let r = sync(&models, &out, &SyncOptions::default()).unwrap();
    assert_eq!(r.removed, [out.join("chain.rs")]);
    assert!(!out.join("chain.rs").exists());
    assert!(
        !std::fs::read_to_string(out.join("mod.rs"))
            .unwrap()
            .contains("chain")
    );
}

#[test]
fn cli_derive_check_detects_a_stale_file() {
    let dir = tempfile::tempdir().unwrap();
    copy_models(&dir.path().join("models"), &["double_pendulum"]);
    let ok = softarm(&["derive"], dir.path());
    assert!(ok.status.success(), "{}", stderr(&ok));
    let check = softarm(&["derive", "--check"], dir.path());
    assert!(check.status.success(), "{}", stderr(&check));
    let f = dir.path().join("generated/double_pendulum.rs");
    let text = std::fs::read_to_string(&f).unwrap();
    std::fs::write(&f, text.replace("pub const DOF", "pub const  DOF")).unwrap();
    let stale = softarm(&["derive", "--check"], dir.path());
    assert!(!stale.status.success());
    assert!(stderr(&stale).contains("stale: ") && stderr(&stale).contains("double_pendulum.rs"));
}

/// A bundled model's generated file may be at most this big (BENCHMARKS.md,
/// build: generated/ under 2 MB for the bundled set).
const FILE_BUDGET: u64 = 300_000;

/// generated/ as a whole (BENCHMARKS.md, build: under 2 MB for the
/// bundled set).
const TOTAL_BUDGET: u64 = 2_000_000;

/// Generated sizes are deterministic, so the budget is a fair test: no
/// model's file over 300 kB, and generated/ within its budget.
#[test]
fn generated_files_keep_their_size_budget() {
    let mut total = 0;
    for e in std::fs::read_dir(root().join("generated")).unwrap() {
        let p = e.unwrap().path();
        let size = std::fs::metadata(&p).unwrap().len();
        total += size;
        let name = p.file_stem().unwrap().to_string_lossy().into_owned();
        if p.extension().is_none_or(|x| x != "rs") || matches!(name.as_str(), "mod" | "lib") {
            continue;
        }
        assert!(
            size <= FILE_BUDGET,
            "generated/{name}.rs is {size} bytes, over the {FILE_BUDGET}-byte budget"
        );
    }
    assert!(
        total <= TOTAL_BUDGET,
        "generated/ is {total} bytes, over its {TOTAL_BUDGET}-byte budget"
    );
}

/// A compiled-in model reads its data from the binary, not from the
/// checkout it was built in: a copy of softarm (a wheel, a binary moved
/// elsewhere) runs its bundled models with their records. The reference is
/// each file on disk; the licence notice beside each data set travels too.
#[test]
fn compiled_in_models_carry_their_data_files_and_notices() {
    let mut carried = 0;
    for m in softarm::generated::MODELS {
        let base = softarm::backend::base_dir(m.name);
        assert!(
            !base.is_absolute() && !base.exists(),
            "{}: its files resolve against {}, a place on disk",
            m.name,
            base.display()
        );
        let model = eomgen::load::load_model(&model_path(m.name), &[]).unwrap();
        let files = model
            .inputs
            .values()
            .filter_map(|i| match i {
                eomgen::model::Input::Csv { file, .. } => Some(file.clone()),
                _ => None,
            })
            .chain(model.compare.iter().map(|c| c.file.clone()));
        for file in files {
            let notice = Path::new(&file).with_file_name("README.md");
            for f in [Path::new(&file), notice.as_path()] {
                let on_disk = std::fs::read_to_string(root().join("models").join(f)).unwrap();
                let path = softarm::data::resolve(&base, f.to_str().unwrap());
                let text = softarm::data::read_text(&path)
                    .unwrap_or_else(|e| panic!("{}: {f:?}: {e:#}", m.name));
                assert_eq!(text, on_disk, "{}: {f:?} differs from the file", m.name);
                carried += 1;
            }
        }
    }
    assert!(carried >= 2, "no bundled model reads a data file any more");
}

/// A compiled-in model has no folder: a record it carries resolves inside
/// it, one it does not (a `--set` of another file) from the current folder,
/// and a compiled-in path it does not carry is an error naming the file.
#[test]
fn a_compiled_in_models_other_files_resolve_from_the_current_folder() {
    use softarm::data::{compiled_in_base, read_text, resolve};
    let base = compiled_in_base("stiff_flop");
    let carried = resolve(&base, "../data/stiff-flop/noload.csv");
    assert_eq!(carried, base.join("../data/stiff-flop/noload.csv"));
    assert_eq!(resolve(&base, "mine.csv"), Path::new("mine.csv"));
    assert_eq!(resolve(&base, "/tmp/mine.csv"), Path::new("/tmp/mine.csv"));
    // Written again into a fitted model's file, the carried path stays.
    assert_eq!(
        resolve(Path::new("elsewhere"), carried.to_str().unwrap()),
        carried
    );
    let err = read_text(&base.join("other.csv")).unwrap_err();
    assert!(format!("{err:#}").contains("other.csv"), "{err:#}");
}
