//! A stage's result read back from the output folder when nothing it depends on changed: the result's file
//! and beside it the key of the inputs it was made from, written after the result (so a run stopped between
//! the two leaves a key that no longer matches, never a stale result under a matching key).

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
