//! Reports a person reads: a [`Report`] document of sections, tables and figures that keep
//! their numbers, rendered to one self-contained HTML file (inline SVG) and to Markdown with
//! SVG files beside it.

mod document;

pub use document::{
    Axis, Block, Envelope, Figure, HeatMap, Lines, Marker, Plot, Report, Section, Series, Stacked,
    Structure, Table,
};
