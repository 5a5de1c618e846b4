//! Content fingerprints: how `analyze` knows that a shot's frames and settings did not change.

use std::fs;
use std::path::Path;
use std::time::UNIX_EPOCH;

use crate::error::{Result, StoreError};

/// A 128-bit FNV-1a hash over typed, length-prefixed fields; [`Fingerprint::finish`] gives 32 hex digits.
///
/// Not cryptographic: it detects changes, it does not resist forgery. Every field is prefixed with a type tag
/// and (for byte strings) its length, so `("ab", "c")` and `("a", "bc")` differ.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Fingerprint {
    state: u128,
}

const FNV_OFFSET: u128 = 0x6c62_272e_07bb_0142_62b8_2175_6295_c58d;
const FNV_PRIME: u128 = 0x0000_0000_0100_0000_0000_0000_0000_013b;

impl Default for Fingerprint {
    fn default() -> Self {
        Self::new()
    }
}

impl Fingerprint {
    /// An empty fingerprint.
    pub fn new() -> Self {
        Self { state: FNV_OFFSET }
    }

    fn raw(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.state ^= u128::from(b);
            self.state = self.state.wrapping_mul(FNV_PRIME);
        }
    }

    /// Adds a byte string (length-prefixed).
    pub fn bytes(&mut self, bytes: &[u8]) -> &mut Self {
        self.raw(b"b");
        self.raw(&(bytes.len() as u64).to_le_bytes());
        self.raw(bytes);
        self
    }

    /// Adds a text (length-prefixed).
    pub fn str(&mut self, s: &str) -> &mut Self {
        self.raw(b"s");
        self.raw(&(s.len() as u64).to_le_bytes());
        self.raw(s.as_bytes());
        self
    }

    /// Adds an integer.
    pub fn u64(&mut self, x: u64) -> &mut Self {
        self.raw(b"u");
        self.raw(&x.to_le_bytes());
        self
    }

    /// Adds a number by its bit pattern (so `0.1` and `0.1000000001` differ, and `-0.0` differs from `0.0`).
    pub fn f64(&mut self, x: f64) -> &mut Self {
        self.raw(b"f");
        self.raw(&x.to_bits().to_le_bytes());
        self
    }

    /// The fingerprint as 32 lowercase hex digits.
    pub fn finish(&self) -> String {
        format!("{:032x}", self.state)
    }
}

/// What [`fingerprint_clip_dir`] reads of each frame file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ClipFingerprint {
    /// Name, size and modification time of each file (cheap: no frame is read). The default.
    #[default]
    Metadata,
    /// Name, size and every byte of each file (reads the whole clip; immune to touched-but-unchanged files
    /// and to edits that keep size and time).
    Content,
}

/// The fingerprint of a clip (a folder of frames or one camera file) and the settings that shape its
/// analysis.
///
/// Definition: the clip's files are every regular file directly inside `dir` (frames and `clip.toml` alike)
/// or, when `dir` is a camera file `NAME.EXT`, every regular file beside it whose name starts with `NAME.`
/// (`shot1.cihx` with its `shot1.mraw` and `shot1.clip.toml`). For each, in byte order of the file names: the
/// name, the length and either the modification time in nanoseconds since the Unix epoch
/// ([`ClipFingerprint::Metadata`]) or the file's bytes, read in chunks ([`ClipFingerprint::Content`]); then
/// `settings`, a text the caller builds from everything else that changes the track (fps, downslope, ball
/// diameter, tracker options, program version …). Subfolders are ignored.
pub fn fingerprint_clip_dir(dir: &Path, settings: &str, mode: ClipFingerprint) -> Result<String> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| StoreError::Io { path, source }
    };
    let (folder, prefix) = if dir.is_file() {
        let stem = dir
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        (dir.parent().unwrap_or(Path::new(".")), Some(format!("{stem}.")))
    } else {
        (dir, None)
    };
    let folder = if folder.as_os_str().is_empty() {
        Path::new(".")
    } else {
        folder
    };
    let mut files = Vec::new();
    for entry in fs::read_dir(folder).map_err(io(dir))? {
        let entry = entry.map_err(io(dir))?;
        if let Some(prefix) = &prefix
            && !entry.file_name().as_encoded_bytes().starts_with(prefix.as_bytes())
        {
            continue;
        }
        let meta = entry.metadata().map_err(io(&entry.path()))?;
        if meta.is_file() {
            files.push((entry.file_name(), entry.path(), meta));
        }
    }
    files.sort_by(|a, b| a.0.as_encoded_bytes().cmp(b.0.as_encoded_bytes()));
    let mut fp = Fingerprint::new();
    fp.str(match mode {
        ClipFingerprint::Metadata => "clip-metadata-v1",
        ClipFingerprint::Content => "clip-content-v1",
    });
    fp.u64(files.len() as u64);
    for (name, path, meta) in &files {
        fp.bytes(name.as_encoded_bytes()).u64(meta.len());
        match mode {
            ClipFingerprint::Metadata => {
                let nanos = meta
                    .modified()
                    .ok()
                    .and_then(|t| t.duration_since(UNIX_EPOCH).ok())
                    .map_or(0, |d| d.as_nanos());
                fp.bytes(&nanos.to_le_bytes());
            }
            ClipFingerprint::Content => {
                // In chunks: a camera file may be many gigabytes.
                use std::io::Read;
                let mut file = fs::File::open(path).map_err(io(path))?;
                let mut buf = vec![0u8; 1 << 20];
                fp.raw(b"b");
                fp.raw(&meta.len().to_le_bytes());
                loop {
                    let n = file.read(&mut buf).map_err(io(path))?;
                    if n == 0 {
                        break;
                    }
                    fp.raw(&buf[..n]);
                }
            }
        }
    }
    fp.str(settings);
    Ok(fp.finish())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_delimited() {
        let a = Fingerprint::new().str("ab").str("c").finish();
        let b = Fingerprint::new().str("a").str("bc").finish();
        assert_ne!(a, b);
        assert_eq!(a.len(), 32);
        assert_eq!(a, Fingerprint::new().str("ab").str("c").finish());
    }

    #[test]
    fn a_camera_file_clip_covers_its_same_named_siblings_only() {
        let dir = std::env::temp_dir().join(format!("bouncelab-fp-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        let write = |name: &str, bytes: &[u8]| fs::write(dir.join(name), bytes).unwrap();
        write("shot1.cihx", b"<cih/>");
        write("shot1.mraw", &[1, 2, 3, 4]);
        write("shot2.cine", b"CI");
        for mode in [ClipFingerprint::Metadata, ClipFingerprint::Content] {
            let fp = || fingerprint_clip_dir(&dir.join("shot1.cihx"), "s", mode).unwrap();
            let before = fp();
            write("shot2.cine", b"CI..");
            assert_eq!(before, fp(), "another clip's file does not count");
            write("shot1.mraw", &[1, 2, 3, 4, 5]);
            assert_ne!(before, fp(), "the data file counts");
            let with_data = fp();
            write("shot1.clip.toml", b"[camera]\nfps = 1000\n");
            assert_ne!(with_data, fp(), "the clip's settings file counts");
            fs::remove_file(dir.join("shot1.clip.toml")).unwrap();
            write("shot1.mraw", &[1, 2, 3, 4]);
        }
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn numbers_by_bits() {
        assert_ne!(
            Fingerprint::new().f64(0.0).finish(),
            Fingerprint::new().f64(-0.0).finish()
        );
        assert_ne!(
            Fingerprint::new().f64(1.0).finish(),
            Fingerprint::new().u64(1.0f64.to_bits()).finish()
        );
    }
}
