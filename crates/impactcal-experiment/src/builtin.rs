//! The built-in shell solver as the runner's in-process solver: a run is the deck rendered
//! into its directory, simulated in this process.

use impactcal_core::{Histories, NodalQuantity};
use impactcal_runner::{InProcessRun, InProcessSolver};
use impactcal_shell::Simulation;
use impactcal_shell::keyword::read_deck;

/// The built-in solver on each run's deck (the run's first input), writing the nodal
/// `quantity` of the deck's history nodes (`*DATABASE_HISTORY_NODE`): what `impactcal
/// simulate --deck <deck> --out <output> --quantity <q>` writes, without a child process.
///
/// Its histories carry no unit, as that command's CSV carries none, so that a batch gives
/// the same results in process and on a process pool (the output specification's `unit`
/// applies to both).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct BuiltInSolver {
    /// The nodal quantity written.
    pub quantity: NodalQuantity,
}

impl BuiltInSolver {
    /// The built-in solver writing `quantity`.
    pub fn new(quantity: NodalQuantity) -> Self {
        BuiltInSolver { quantity }
    }
}

impl InProcessSolver for BuiltInSolver {
    /// # Errors
    /// A message when the run has no deck, the deck does not read, the model does not set
    /// up or the run fails, or the deck has no history nodes.
    fn solve(&self, run: &InProcessRun<'_>) -> Result<Histories, String> {
        let Some(deck) = run.inputs.first() else {
            return Err("the built-in solver needs a deck template".into());
        };
        let deck = read_deck(run.dir.join(deck)).map_err(|e| e.to_string())?;
        let mut sim = Simulation::new(&deck.model).map_err(|e| e.to_string())?;
        let result = sim.run().map_err(|e| e.to_string())?;
        let h = result
            .histories(self.quantity)
            .ok_or_else(|| "the deck has no history nodes (*DATABASE_HISTORY_NODE)".to_string())?;
        Ok(h.clone().with_unit(String::new()))
    }
}
