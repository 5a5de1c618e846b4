//! A stage's result read back from the output folder when nothing it depends on changed: the result's file
//! and beside it the key of the inputs it was made from. The key is removed before the result is made again
//! and written after it, so a run stopped in between leaves no key (the next run makes the result again),
//! never a new result under an old key.

use crate::{AnalyzeError, ShotData};
use bouncelab_store::Fingerprint;
use serde::de::DeserializeOwned;
use std::path::Path;

/// The `T` in `path`, when `key_path` holds `key`.
pub(crate) fn read_back<T: DeserializeOwned>(path: &Path, key_path: &Path, key: &str) -> Option<T> {
    if !std::fs::read_to_string(key_path).is_ok_and(|k| k.trim() == key) {
        return None;
    }
    std::fs::read_to_string(path)
        .ok()
        .and_then(|t| serde_json::from_str::<T>(&t).ok())
}

/// `key` extended with every shot's clip name and measurement, the inputs every stage after measuring
/// depends on.
pub(crate) fn add_shots(key: &mut Fingerprint, shots: &[&ShotData]) {
    for s in shots {
        key.str(&s.clip)
            .str(&serde_json::to_string(&s.measured).unwrap_or_default());
    }
}

/// Removes the key at `key_path` before its result is made again (no key there is fine).
pub(crate) fn forget(key_path: &Path) -> Result<(), AnalyzeError> {
    match std::fs::remove_file(key_path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(AnalyzeError::Io {
            path: key_path.to_path_buf(),
            source: e,
        }),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_result_is_read_back_only_under_its_key_and_not_once_the_key_is_forgotten() {
        let dir = tempfile::tempdir().unwrap();
        let (path, key_path) = (dir.path().join("r.json"), dir.path().join(".r-inputs"));
        std::fs::write(&path, "[1.5, 2.25]").unwrap();
        assert_eq!(read_back::<Vec<f64>>(&path, &key_path, "k1"), None, "no key yet");
        std::fs::write(&key_path, "k1").unwrap();
        assert_eq!(read_back::<Vec<f64>>(&path, &key_path, "k1"), Some(vec![1.5, 2.25]));
        assert_eq!(read_back::<Vec<f64>>(&path, &key_path, "k2"), None, "other inputs");
        // A run making the result again forgets the key first; stopped before writing the new key, the next
        // run reads nothing back.
        forget(&key_path).unwrap();
        std::fs::write(&path, "[3.0]").unwrap();
        assert_eq!(read_back::<Vec<f64>>(&path, &key_path, "k1"), None);
        forget(&key_path).unwrap();
    }
}
