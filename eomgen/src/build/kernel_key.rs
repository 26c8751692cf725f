//! The key a compiled kernel is linked by: a digest of its tapes, so that
//! equal keys compute the same. A link cell's (`runtime::links::
//! CompiledCell`: its cell, tangent and pose tapes) and a part kernel's
//! (`runtime::parts::CompiledPart`: its kernel and tangent) are found so
//! among the compiled-in models' by systems no build has seen.

use runtime::Tape;

/// The digest of `tapes`, in order: 24 hexadecimal digits.
pub fn kernel_key(tapes: &[&Tape]) -> String {
    use sha2::{Digest, Sha256};
    let mut h = Sha256::new();
    for t in tapes {
        h.update(
            serde_json::to_string(t)
                .expect("a tape serialises")
                .as_bytes(),
        );
        h.update(b"\n");
    }
    h.finalize()
        .iter()
        .take(12)
        .map(|b| format!("{b:02x}"))
        .collect()
}
