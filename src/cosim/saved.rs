//! Saved states: in memory for a rollback, and as bytes (FMI serialised states, the
//! zenoh `state` queryable). The bytes are the simulation's state (see
//! [`crate::scene::state`]) followed by the component's wall drives and means, and a
//! CRC-32 of all of it. The life-cycle mode is not part of a state: it is the master's.

use super::CosimError;
use super::component::{Component, ComponentState, Mode, RUNNING, WallDrive, WallMeans};
use crate::scene::state_bytes::starts_as_state;
use crate::scene::{SimState, StateError, StateReader, StateWriter};

impl Component {
    /// The state as it is now (initialisation, step or terminated mode); on ranks
    /// the whole run's, on every rank (collective).
    pub fn save_state(&self) -> Result<ComponentState, CosimError> {
        self.expect_mode(
            "saving the state",
            &[Mode::Initialisation, Mode::Step, Mode::Terminated],
            RUNNING,
        )?;
        Ok(ComponentState {
            fingerprint: self.fingerprint,
            sim: self.whole_state(self.sim.as_ref().expect("running").share_snapshot()),
            drives: self.drives.clone(),
            means: self.means.clone(),
        })
    }

    /// Goes back to a saved state (of this scene; on ranks collective, saved on
    /// any number of ranks or in one process).
    pub fn restore_state(&mut self, state: &ComponentState) -> Result<(), CosimError> {
        self.expect_mode(
            "restoring a state",
            &[Mode::Initialisation, Mode::Step, Mode::Terminated],
            RUNNING,
        )?;
        if state.fingerprint != self.fingerprint {
            return Err(CosimError::State(StateError::OtherScene {
                found: state.fingerprint,
                expected: self.fingerprint,
            }));
        }
        self.install_state(&state.sim)?;
        self.gather();
        // The life cycle is the master's: a state saved in step mode and restored
        // during initialisation leaves the instance in initialisation.
        self.drives = state.drives.clone();
        self.means = state.means.clone();
        Ok(())
    }

    /// A saved state as bytes.
    pub fn state_to_bytes(&self, state: &ComponentState) -> Vec<u8> {
        let mut w = StateWriter::default();
        state.sim.write(self.fingerprint, &mut w);
        for (d, m) in state.drives.iter().zip(&state.means) {
            match d {
                WallDrive::Prescribed => w.u64(0),
                WallDrive::Velocity { linear, angular } => {
                    w.u64(1);
                    w.vec3(linear);
                    w.vec3(angular);
                }
                WallDrive::Pose {
                    position,
                    orientation,
                } => {
                    w.u64(2);
                    w.vec3(position);
                    orientation.iter().for_each(|x| w.f64(*x));
                }
            }
            w.vec3(&m.force);
            w.vec3(&m.torque);
            w.f64(m.power);
        }
        w.into_checked()
    }

    /// A state from bytes written by [`Component::state_to_bytes`] for this scene.
    /// Needs the simulation (initialisation mode or later).
    pub fn state_from_bytes(&self, bytes: &[u8]) -> Result<ComponentState, CosimError> {
        self.expect_mode(
            "reading a state",
            &[Mode::Initialisation, Mode::Step, Mode::Terminated],
            RUNNING,
        )?;
        if !starts_as_state(bytes) {
            return Err(StateError::NotAState.into());
        }
        let mut r = StateReader::checked(bytes)?;
        let sim = SimState::read(self.fingerprint, &mut r)?;
        self.sim.as_ref().expect("running").check_state(&sim)?;
        let corrupt = |m: &str| CosimError::State(StateError::Corrupt(m.into()));
        let mut drives = Vec::new();
        let mut means = Vec::new();
        for _ in 0..self.drives.len() {
            drives.push(match r.u64()? {
                0 => WallDrive::Prescribed,
                1 => WallDrive::Velocity {
                    linear: r.vec3()?,
                    angular: r.vec3()?,
                },
                2 => WallDrive::Pose {
                    position: r.vec3()?,
                    orientation: [r.f64()?, r.f64()?, r.f64()?, r.f64()?],
                },
                _ => return Err(corrupt("unknown wall drive")),
            });
            means.push(WallMeans {
                force: r.vec3()?,
                torque: r.vec3()?,
                power: r.f64()?,
            });
        }
        if !r.is_done() {
            return Err(corrupt("trailing bytes after the state"));
        }
        Ok(ComponentState {
            fingerprint: self.fingerprint,
            sim,
            drives,
            means,
        })
    }
}
