//! A service on MPI ranks (`mpirun -np N talus serve`): rank 0 is the zenoh node;
//! every request that changes the component's state (a step, a state saved or
//! restored, a call of the life cycle) is handed to every other rank before rank 0 answers it, and every
//! rank's service makes the same call with the same bytes, so the ranks' components
//! stay one decomposed run (see [`crate::cosim`]'s component on ranks); so is a
//! `<key>/fluid` request, whose particles every rank gathers to rank 0. The other
//! requests read what rank 0 holds and are answered by it alone.

use crate::cosim::{Component, CosimError, Mode};
use crate::engine::exchange::Ranks;

use super::Service;

/// What rank 0 tells the other ranks: the first byte of each broadcast, the
/// request's payload after it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub(super) enum Call {
    /// The node stopped: terminate the component (writes the outputs).
    Stop = 0,
    /// A `<key>/step` request.
    Step = 1,
    /// A `<key>/state` request.
    State = 2,
    /// A `<key>/call` request that changes the component.
    Life = 3,
    /// A `<key>/fluid` request (each particle's fluid is gathered from every rank).
    Fluid = 4,
}

impl Call {
    fn of(byte: u8) -> Option<Call> {
        [Call::Stop, Call::Step, Call::State, Call::Life, Call::Fluid]
            .into_iter()
            .find(|c| *c as u8 == byte)
    }
}

impl Service {
    /// Serves this rank's `component` of a run on `ranks` (collective calls go
    /// through `ranks`; the component holds an exchange of its own): on rank 0
    /// behind the node, on the others through [`Service::follow`].
    pub fn on_ranks(component: Component, ranks: Box<dyn Ranks>) -> Self {
        let mut service = Service::new(component);
        service.ranks = Some(ranks);
        service
    }

    /// On rank 0 of ranks: hands `call` with `payload` to the other ranks.
    pub(super) fn tell_ranks(&self, call: Call, payload: &[u8]) {
        if let Some(ranks) = self.ranks.as_ref().filter(|r| r.rank() == 0) {
            let mut message = vec![call as u8];
            message.extend_from_slice(payload);
            ranks.announce(&message);
        }
    }

    /// On a rank other than 0: makes rank 0's calls until it stops, then
    /// terminates the component with the others.
    pub fn follow(mut self) -> Result<Component, CosimError> {
        let ranks = self
            .ranks
            .take()
            .expect("a service on ranks follows rank 0");
        assert_ne!(ranks.rank(), 0, "rank 0 leads");
        loop {
            let message = ranks.announce(&[]);
            let (&call, payload) = message.split_first().expect("a call byte");
            match Call::of(call).expect("rank 0 sends known calls") {
                Call::Stop => break,
                // The replies are rank 0's to send.
                Call::Step => drop(self.step(payload)),
                Call::State => drop(self.state(payload)),
                Call::Life => drop(self.call(payload)),
                Call::Fluid => drop(self.fluid(payload)),
            }
        }
        end(self.component)
    }

    /// Ends serving: on rank 0 of ranks tells the others to stop, then terminates
    /// the component if it runs (collective on ranks); returns it.
    pub fn finish(self) -> Result<Component, CosimError> {
        self.tell_ranks(Call::Stop, &[]);
        end(self.component)
    }
}

/// Terminates `component` (writes its outputs) unless a master already did, or
/// reset it and left it before initialisation.
fn end(mut component: Component) -> Result<Component, CosimError> {
    if matches!(component.mode(), Mode::Initialisation | Mode::Step) {
        component.terminate()?;
    }
    Ok(component)
}
