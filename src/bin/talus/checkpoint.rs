//! Checkpoint files of `talus run` (their bytes: `talus::checkpoint`).
//!
//! A checkpoint is written to a temporary file, synced, and renamed over
//! `checkpoint.talus` after the one there was renamed to `checkpoint.prev.talus`: a
//! process killed at any moment leaves at least one whole checkpoint (the newest, or
//! the one before it while the new one is being written). A resume takes the newest
//! that is whole and of this scene, and says why it passed over the other.

use std::fs::{self, File};
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{Context, Result, bail};
use talus::checkpoint::Checkpoint;
use talus::scene::{Scene, StateError};

/// The newest checkpoint.
pub const FILE: &str = "checkpoint.talus";
/// The one before it.
pub const PREVIOUS: &str = "checkpoint.prev.talus";
/// Where a checkpoint is written before it is renamed.
const TEMP: &str = "checkpoint.talus.tmp";

/// For the crash tests only: a pause in the middle of writing the temporary file and
/// between the two renames, so that a test can kill the process there.
fn test_pause() {
    if let Some(ms) = std::env::var("TALUS_TEST_CHECKPOINT_PAUSE_MS")
        .ok()
        .and_then(|v| v.parse().ok())
    {
        std::thread::sleep(Duration::from_millis(ms));
    }
}

/// Writes `bytes` as the newest checkpoint in `dir`, keeping the one before.
pub fn write(dir: &Path, bytes: &[u8]) -> io::Result<()> {
    let temp = dir.join(TEMP);
    {
        let mut file = File::create(&temp)?;
        let half = bytes.len() / 2;
        file.write_all(&bytes[..half])?;
        file.flush()?;
        test_pause();
        file.write_all(&bytes[half..])?;
        file.sync_all()?;
    }
    let newest = dir.join(FILE);
    if newest.exists() {
        fs::rename(&newest, dir.join(PREVIOUS))?;
    }
    test_pause();
    fs::rename(&temp, &newest)?;
    // The renames themselves reach the disk.
    File::open(dir)?.sync_all()
}

/// Why a checkpoint file was passed over, in words.
fn refusal(file: &Path, e: &StateError) -> String {
    let what = match e {
        StateError::NotAState => {
            "not a checkpoint of this talus version (format TALUSCK1)".to_string()
        }
        StateError::OtherScene { .. } => {
            "written for another scene or another talus version (was the scene file changed since?)"
                .to_string()
        }
        other => other.to_string(),
    };
    format!("{}: {what}", file.display())
}

/// The scene and the newest usable checkpoint of the run in `dir`; `scene` (when
/// given) must be the checkpoint's scene, else the scene the checkpoint names is
/// loaded.
pub fn resume(dir: &Path, scene: Option<&Path>) -> Result<(Scene, Checkpoint)> {
    let mut refused = Vec::new();
    let mut loaded: Option<Scene> = None;
    for name in [FILE, PREVIOUS] {
        let file = dir.join(name);
        let bytes = match fs::read(&file) {
            Ok(b) => b,
            Err(e) if e.kind() == io::ErrorKind::NotFound => continue,
            Err(e) => {
                refused.push(format!("{}: {e}", file.display()));
                continue;
            }
        };
        let named = match Checkpoint::scene_of(&bytes) {
            Ok(p) => p,
            Err(e) => {
                refused.push(refusal(&file, &e));
                continue;
            }
        };
        if loaded.is_none() {
            let path: PathBuf = scene.map_or(named, Path::to_path_buf);
            let s = crate::run::load(&path).with_context(|| {
                format!(
                    "cannot load the scene {} of the checkpoint {}",
                    path.display(),
                    file.display()
                )
            })?;
            loaded = Some(s);
        }
        let s = loaded.as_ref().expect("loaded");
        match Checkpoint::from_bytes(&bytes, s.fingerprint()) {
            Ok(checkpoint) => {
                for r in &refused {
                    eprintln!("warning: passed over {r}");
                }
                return Ok((loaded.expect("loaded"), checkpoint));
            }
            Err(e) => refused.push(refusal(&file, &e)),
        }
    }
    if refused.is_empty() {
        bail!(
            "{}: no checkpoint to resume from ({FILE} or {PREVIOUS}); a run writes them with [output] checkpoint_interval, --checkpoint-every, or when interrupted",
            dir.display()
        );
    }
    bail!(
        "no usable checkpoint in {}:\n  {}",
        dir.display(),
        refused.join("\n  ")
    )
}
