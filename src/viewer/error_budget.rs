//! The error budget measured from the viewer (the panel's button, the step `budget`): the view as
//! it is, at most [`BUDGET_WIDTH`] pixels wide, drawn ten times or so with each approximation
//! swapped and traced once (`crate::budget`), while the window waits.

/// The widest view the panel's error budget is measured at: wider views are measured smaller.
#[cfg(not(target_arch = "wasm32"))]
pub(super) const BUDGET_WIDTH: u32 = 480;

/// The last error budget measured, as the report `mirador budget` prints, and whether one is due
/// once the view has its size.
#[derive(Default)]
pub(in crate::viewer) struct ErrorBudget {
    pub report: Option<String>,
    pub next: bool,
}
