//! The card parsers, one module per family of keywords; [`super::reader::TABLE`] maps each
//! keyword to its parser.

pub(super) mod contacts;
pub(super) mod controls;
pub(super) mod loads;
pub(super) mod materials;
pub(super) mod mesh;
pub(super) mod sets;
pub(super) mod walls;

/// Standard widths of the 10-column cards.
pub(super) const W10: &[usize] = &[10];
