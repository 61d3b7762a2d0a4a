//! The fluid side of a running [`Simulation`]: what a coupled CFD code sets and reads.

use nalgebra::Vector3;

use super::Simulation;
use super::fluid_ranks::update_fluid_on_ranks;
use super::spec::UpdateInterval;
use crate::Real;
use crate::world::FluidField;

/// Why fluid inputs were refused.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum FluidError {
    /// The scene has no `[fluid]`.
    #[error("the scene has no [fluid] section")]
    NoFluid,
    /// An input of the wrong length.
    #[error("{what}: {got} values for {cells} cells")]
    Length {
        /// The input.
        what: &'static str,
        /// Values given.
        got: usize,
        /// Cells of the grid.
        cells: usize,
    },
    /// A value that is not finite.
    #[error("{what}: cell {cell} is not finite")]
    NotFinite {
        /// The input.
        what: &'static str,
        /// The cell's flat index.
        cell: usize,
    },
}

impl Simulation {
    /// The fluid field, with a `[fluid]` section.
    pub fn fluid(&self) -> Option<&FluidField> {
        self.world.fluid.as_ref()
    }

    /// Splits the particles' volumes among the fluid's cells again (the solid
    /// fractions, mean particle velocities and exchange weights). The simulation
    /// does it every `update_interval` steps, or at each communication step
    /// ([`Self::start_communication_step`]); a coupled code may ask for it at its
    /// own exchange. On ranks collective, with one process's bits.
    pub fn update_fluid(&mut self) {
        let w = &mut self.world;
        let Some(fluid) = w.fluid.as_mut() else {
            return;
        };
        match self.backend.share() {
            Some(share) => update_fluid_on_ranks(share, w),
            None => fluid.update(&w.particles, &w.body_types),
        }
        self.backend.fluid_changed(&self.world);
    }

    /// Sets the fluid's velocity in every cell (flat order of the grid); on error
    /// nothing changed.
    pub fn set_fluid_velocity(&mut self, velocity: &[Vector3<Real>]) -> Result<(), FluidError> {
        self.set_cells("fluid velocity", velocity, |f| &mut f.velocity)
    }

    /// Sets the pressure gradient in every cell; on error nothing changed.
    pub fn set_pressure_gradient(&mut self, gradient: &[Vector3<Real>]) -> Result<(), FluidError> {
        self.set_cells("pressure gradient", gradient, |f| &mut f.pressure_gradient)
    }

    /// The mean force per cell the particles put on the fluid since the last call
    /// (the drag they received, with the opposite sign; N). On ranks collective:
    /// the whole run's on rank 0, an empty list on the others.
    pub fn take_momentum_source(&mut self) -> Result<Vec<Vector3<Real>>, FluidError> {
        if self.world.fluid.is_none() {
            return Err(FluidError::NoFluid);
        }
        let source = self.whole_momentum_source().unwrap_or_default();
        self.restart_fluid_exchange();
        Ok(source)
    }

    /// What a coupled run does at the start of each communication step, once the
    /// coupled code has set its fields: starts the sums of the momentum exchange
    /// again (so that [`FluidField::momentum_source`] is the mean over the step)
    /// and, with `update_interval = "communication"`, splits the particles' volumes
    /// among the cells again.
    pub fn start_communication_step(&mut self) {
        self.restart_fluid_exchange();
        if self.fluid_interval == Some(UpdateInterval::Communication) {
            self.update_fluid();
        }
    }

    /// Starts the sums of the momentum exchange again.
    pub fn restart_fluid_exchange(&mut self) {
        if let Some(fluid) = self.world.fluid.as_mut() {
            fluid.restart_exchange();
            self.backend.fluid_changed(&self.world);
        }
    }

    fn set_cells(
        &mut self,
        what: &'static str,
        values: &[Vector3<Real>],
        field: impl FnOnce(&mut FluidField) -> &mut Vec<Vector3<Real>>,
    ) -> Result<(), FluidError> {
        let fluid = self.world.fluid.as_mut().ok_or(FluidError::NoFluid)?;
        let cells = fluid.grid.len();
        if values.len() != cells {
            return Err(FluidError::Length {
                what,
                got: values.len(),
                cells,
            });
        }
        if let Some(cell) = values.iter().position(|v| !v.iter().all(|x| x.is_finite())) {
            return Err(FluidError::NotFinite { what, cell });
        }
        field(fluid).copy_from_slice(values);
        self.backend.fluid_changed(&self.world);
        Ok(())
    }
}
