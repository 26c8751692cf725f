//! Files written whole or not at all (`eomgen::atomic_write`).

use eomgen::atomic_write::write_atomic;

/// The file holds the new bytes, nothing is left beside it, and a
/// write that cannot land (its folder is missing) leaves nothing.
#[test]
fn writes_whole_and_leaves_no_temporary() {
    let dir = std::env::temp_dir().join(format!("eomgen-atomic-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("out.csv");
    write_atomic(&path, b"old").unwrap();
    write_atomic(&path, b"new").unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), b"new");
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
    assert!(write_atomic(&dir.join("missing/out.csv"), b"x").is_err());
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
    std::fs::remove_dir_all(&dir).unwrap();
}
