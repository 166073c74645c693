//! LS-DYNA keyword decks: the subset this solver supports, in and out.
//!
//! [`parse_deck`] / [`read_deck`] turn a deck into a [`ShellModel`](crate::ShellModel); [`write_deck`] writes a
//! model back in fixed-width format, and reading what it wrote gives the same model.
//!
//! Cards may be fixed-width (the widths of each keyword's manual page: 8/16 for `*NODE`,
//! 8 for `*ELEMENT_SHELL`, 20 for curve points, 10 otherwise; the long format and 10-digit
//! ids widen them) or comma-separated; `$` starts a comment line; a blank field takes the
//! default. Every card of a keyword is read or the keyword is refused: a card the keyword
//! does not take is an error naming its line. Unsupported keywords are an error naming the
//! keyword and the line, except the output-only keywords of [`IGNORED_KEYWORDS`] and the
//! `*SENSOR` keywords, which produce a warning. Unsupported values of supported fields (for
//! example a coordinate system id, a box, mass scaling) are errors too. The supported
//! keywords and fields are listed card by card in `docs/shell-solver.md`.
//!
//! Layout: `source` (lines and includes), `blocks` (keywords and their card format),
//! `cards` (fields and numbers), `params` (`*PARAMETER`, `*PARAMETER_EXPRESSION`),
//! `reader` (the dispatch table and the deck), `families` (one card parser per keyword,
//! by family), `writer`.

// Deck flags and defaults are exact values (0, 1): compare them exactly.
#[allow(clippy::float_cmp)]
mod blocks;
#[allow(clippy::float_cmp)]
mod cards;
#[allow(clippy::float_cmp)]
mod families;
mod params;
#[allow(clippy::float_cmp)]
mod reader;
mod source;
#[allow(clippy::float_cmp)]
mod writer;

pub use params::DeckParameter;
pub use reader::{Deck, IGNORED_KEYWORDS, parse_deck, read_deck};
pub use writer::{write_deck, write_deck_file};
