//! The document a report is rendered from: sections of text, tables and figures, each figure
//! holding the numbers it plots (never pixels). A study or a closed loop builds a
//! [`Report`]; the renderers turn the same document into a self-contained HTML file and a
//! Markdown file with SVG figures beside it.

/// A whole report: a title, a lead paragraph and its sections, in reading order.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// The document's title (the HTML `<title>` and the top heading).
    pub title: String,
    /// Paragraphs under the title, before the first section (the verdicts in short).
    pub lead: Vec<String>,
    /// The sections, in order.
    pub sections: Vec<Section>,
}

/// One titled section: blocks in order.
#[derive(Debug, Clone, PartialEq)]
pub struct Section {
    /// The heading.
    pub heading: String,
    /// Paragraphs, tables and figures, in reading order.
    pub blocks: Vec<Block>,
}

/// A piece of a section.
#[derive(Debug, Clone, PartialEq)]
pub enum Block {
    /// A paragraph of plain text (no markup; renderers escape it).
    Paragraph(String),
    /// A table of text cells.
    Table(Table),
    /// A figure with its caption.
    Figure(Figure),
}

/// A table of text cells: every row has as many cells as the header.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// A caption above the table.
    pub caption: String,
    /// Column headings.
    pub header: Vec<String>,
    /// Rows of cells, each `header.len()` long.
    pub rows: Vec<Vec<String>>,
}

/// A figure: what it plots and a caption under it. `name` is a file stem (`[a-z0-9-]+`,
/// unique within the report) for the SVG file the Markdown renderer writes.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// File stem of the figure's SVG file (`fig-m1-table1` -> `fig-m1-table1.svg`).
    pub name: String,
    /// Caption, under the figure.
    pub caption: String,
    /// The data plotted.
    pub plot: Plot,
}

/// The kinds of figure a calibration report draws.
#[derive(Debug, Clone, PartialEq)]
pub enum Plot {
    /// Curves over a common abscissa (Q(t) of test, baseline and calibrated; one sensor's
    /// histories; a residual's time pattern).
    Lines(Lines),
    /// An envelope (lower/upper band) with curves over it and marked intervals (the M1
    /// figure: the ensemble's min/max of Q(t) and the test's Q_e(t), exits shaded).
    Envelope(Envelope),
    /// A matrix as a heat map with a bar of weights along each axis (the M2 figure: MAC of
    /// test shapes vs model shapes, with each side's shape contributions).
    HeatMap(HeatMap),
    /// Series stacked over a common abscissa with one more curve drawn above them on its own
    /// axis (first-order Sobol' indices per parameter vs time under Q(t)).
    Stacked(Stacked),
    /// Points of a structure seen in two projections with some points marked (sensor
    /// locations; a residual's sensor pattern as marker colours).
    Structure(Structure),
}

/// A named curve.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend entry.
    pub name: String,
    /// Ordinates, one per abscissa value of the plot.
    pub values: Vec<f64>,
}

impl Series {
    /// A curve named `name` with ordinates `values`.
    pub fn new(name: impl Into<String>, values: Vec<f64>) -> Self {
        Series {
            name: name.into(),
            values,
        }
    }
}

/// An axis: its label with the unit, e.g. `"time (s)"`, `"Q (in/s)"`.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// Label including the unit in parentheses.
    pub label: String,
}

impl Axis {
    /// An axis labelled `label` (quantity and unit, e.g. `"time (s)"`).
    pub fn new(label: impl Into<String>) -> Self {
        Axis {
            label: label.into(),
        }
    }
}

/// Curves over a common abscissa.
#[derive(Debug, Clone, PartialEq)]
pub struct Lines {
    /// The abscissa values (ascending), shared by every series.
    pub x: Vec<f64>,
    /// Abscissa axis.
    pub x_axis: Axis,
    /// Ordinate axis.
    pub y_axis: Axis,
    /// The curves, each `x.len()` long.
    pub series: Vec<Series>,
}

/// A band with curves and marked intervals.
#[derive(Debug, Clone, PartialEq)]
pub struct Envelope {
    /// The abscissa values (ascending).
    pub x: Vec<f64>,
    /// Abscissa axis.
    pub x_axis: Axis,
    /// Ordinate axis.
    pub y_axis: Axis,
    /// Legend entry of the band (e.g. `"ensemble min/max (150 runs)"`).
    pub band_name: String,
    /// Lower edge of the band, `x.len()` long.
    pub lower: Vec<f64>,
    /// Upper edge of the band, `x.len()` long, `upper >= lower`.
    pub upper: Vec<f64>,
    /// Curves over the band (the test first), each `x.len()` long.
    pub series: Vec<Series>,
    /// Intervals `[start, end]` of the abscissa to shade (where the test leaves the band).
    pub marked: Vec<(f64, f64)>,
}

/// A matrix drawn as a heat map, with bars of weights along its axes.
#[derive(Debug, Clone, PartialEq)]
pub struct HeatMap {
    /// Values, `rows x columns`, row-major (`values[i][j]`); colour scale from `range`.
    pub values: Vec<Vec<f64>>,
    /// Colour scale limits `(low, high)`, e.g. `(0.0, 1.0)` for MAC values.
    pub range: (f64, f64),
    /// Label of the row axis (e.g. `"test shape"`).
    pub row_axis: Axis,
    /// Label of the column axis (e.g. `"baseline model shape"`).
    pub column_axis: Axis,
    /// Weights of the rows drawn as a bar beside the map (e.g. test shape contributions in
    /// percent), `values.len()` long, or empty for none.
    pub row_weights: Vec<f64>,
    /// Weights of the columns drawn as a bar above the map, `values[0].len()` long, or empty.
    pub column_weights: Vec<f64>,
    /// What the row weights are, with their unit (e.g. `"model shape contribution (%)"`):
    /// the description under the bars beside the map. Must not be blank when `row_weights`
    /// is not empty.
    pub row_weights_axis: Axis,
    /// What the column weights are, with their unit (e.g. `"test shape contribution (%)"`):
    /// the description beside the bars above the map. Must not be blank when
    /// `column_weights` is not empty.
    pub column_weights_axis: Axis,
    /// Cells `(row, column)` to outline (the optimal pairing).
    pub marked: Vec<(usize, usize)>,
    /// Write each cell's value inside it (for small matrices).
    pub annotate: bool,
}

/// Stacked series under a curve on its own axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Stacked {
    /// The abscissa values (ascending).
    pub x: Vec<f64>,
    /// Abscissa axis (shared by both panels).
    pub x_axis: Axis,
    /// Ordinate axis of the stacked panel (e.g. `"first-order index"`).
    pub y_axis: Axis,
    /// The stacked series (non-negative values; the stack may exceed 1 where indices do).
    pub stacked: Vec<Series>,
    /// Ordinate axis of the curve drawn above (e.g. `"Q (in/s)"`).
    pub top_axis: Axis,
    /// The curve above (e.g. the baseline Q(t)), `x.len()` long.
    pub top: Series,
}

/// Points of a structure in two projections (plan `x-y` and side `x-z`), some marked.
#[derive(Debug, Clone, PartialEq)]
pub struct Structure {
    /// Every point of the structure (drawn small and grey): `[x, y, z]`.
    pub points: Vec<[f64; 3]>,
    /// Length unit of the coordinates (e.g. `"in"`).
    pub unit: String,
    /// Marked points with their labels (sensor labels), drawn large.
    pub marked: Vec<Marker>,
    /// What the markers' values are, with their unit (e.g. `"change from nominal (%)"`),
    /// written along the colour bar. Must not be blank when a marker carries a value.
    pub value_axis: Axis,
    /// Half-width `L > 0` of the colour scale (values from `-L` to `+L`); `None` takes
    /// `max |value|` over the markers. Give figures that are to be compared the same `L`.
    pub limit: Option<f64>,
}

/// A marked point of a [`Structure`].
#[derive(Debug, Clone, PartialEq)]
pub struct Marker {
    /// Label written beside the point (e.g. a channel label `"1021.z"`); may be empty.
    pub label: String,
    /// Its coordinates `[x, y, z]`.
    pub at: [f64; 3],
    /// A value coloured on a diverging scale (e.g. a residual pattern entry), or `None` for
    /// a plain marker.
    pub value: Option<f64>,
}
