//! A run's checkpoint as bytes: what `talus run --resume` needs to continue a run so
//! that its outputs equal, bit for bit, those of a run never stopped.
//!
//! Layout (little-endian, in a checked container: a CRC-32 of all before it ends the
//! bytes, so a truncated or damaged checkpoint is refused before anything is read):
//!
//! ```text
//! "TALUSCK1"  magic (the digit is the format's version)
//! u64         the scene's fingerprint (Scene::fingerprint: its text and talus version)
//! blob        the scene file's path (UTF-8), for `--resume` without a scene argument
//! blob        JSON: the run's progress and the outputs' cursor (output::OutputCursor)
//! ...         the simulation's state, in the format of the Component's saved states
//! u32         CRC-32
//! ```
//!
//! Writing the file (temporary file, fsync, rename, the last two kept) is the
//! command line's; this module knows only the bytes.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::output::OutputCursor;
use crate::scene::{SimState, StateError, StateReader, StateWriter};

const MAGIC: &[u8; 8] = b"TALUSCK1";

/// The run's counters that a resumed run carries on (for the summary's figures).
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct RunProgress {
    /// Sum over the steps of the contacts.
    pub contact_sum: u64,
    /// Sum over the steps of the particles integrated.
    pub particle_steps: u64,
    /// Wall-clock seconds run before this checkpoint (over all resumptions).
    pub wall_clock_s: f64,
    /// Worker threads of the run that wrote it.
    pub threads: usize,
}

/// The run record of a checkpoint (its JSON blob).
#[derive(Clone, Debug, Serialize, Deserialize)]
struct Record {
    progress: RunProgress,
    output: OutputCursor,
}

/// What a checkpoint holds.
#[derive(Clone, Debug)]
pub struct Checkpoint {
    /// The scene file of the run.
    pub scene: PathBuf,
    /// The run's counters.
    pub progress: RunProgress,
    /// Where the outputs stood.
    pub output: OutputCursor,
    /// The simulation's state.
    pub sim: SimState,
}

impl Checkpoint {
    /// The checkpoint as bytes, for the scene with this `fingerprint`.
    pub fn to_bytes(&self, fingerprint: u64) -> Vec<u8> {
        let mut w = StateWriter::default();
        w.magic(MAGIC);
        w.u64(fingerprint);
        w.blob(self.scene.to_string_lossy().as_bytes());
        let record = Record {
            progress: self.progress.clone(),
            output: self.output.clone(),
        };
        w.blob(&serde_json::to_vec(&record).expect("a record serialises"));
        self.sim.write(fingerprint, &mut w);
        w.into_checked()
    }

    /// The scene file a checkpoint was written for (once its checksum matched).
    pub fn scene_of(bytes: &[u8]) -> Result<PathBuf, StateError> {
        let mut r = Self::header(bytes)?;
        r.u64()?;
        scene_path(&mut r)
    }

    /// Reads a checkpoint of the scene with this `fingerprint`.
    pub fn from_bytes(bytes: &[u8], fingerprint: u64) -> Result<Checkpoint, StateError> {
        let mut r = Self::header(bytes)?;
        let found = r.u64()?;
        if found != fingerprint {
            return Err(StateError::OtherScene {
                found,
                expected: fingerprint,
            });
        }
        let scene = scene_path(&mut r)?;
        let record: Record = serde_json::from_slice(r.blob()?)
            .map_err(|e| StateError::Corrupt(format!("the run record: {e}")))?;
        let sim = SimState::read(fingerprint, &mut r)?;
        if !r.is_done() {
            return Err(StateError::Corrupt("trailing bytes after the state".into()));
        }
        Ok(Checkpoint {
            scene,
            progress: record.progress,
            output: record.output,
            sim,
        })
    }

    /// A reader after the magic, once the checksum matched.
    fn header(bytes: &[u8]) -> Result<StateReader<'_>, StateError> {
        if !bytes.starts_with(MAGIC) {
            return Err(StateError::NotAState);
        }
        let mut r = StateReader::checked(bytes)?;
        r.magic(MAGIC);
        Ok(r)
    }
}

fn scene_path(r: &mut StateReader) -> Result<PathBuf, StateError> {
    let path = std::str::from_utf8(r.blob()?)
        .map_err(|_| StateError::Corrupt("the scene path is not UTF-8".into()))?;
    Ok(PathBuf::from(path))
}
