//! Writes the figures of the airframe demo's study report that are drawn on the structure,
//! on the real coarse airframe (its mesh only; no simulation): the 41 sensors the demo
//! placed (`impactcal demo`, Table 2; mirror pairs such as 237.y/253.y coincide in the
//! side view), a signed pattern over the 24 channels of the closed-loop demo (as its
//! residual's sensor pattern is drawn), an impact shape's vertical entries at every node,
//! and the reveal's hidden change. It names on stderr each sensor that has a label in
//! neither view of its figure. The headless-browser check (`tests/browser/check_report.sh`) renders it and
//! requires that no two labels overlap.
//!
//! ```text
//! cargo run --example airframe_report -- OUT_DIR
//! ```

use std::path::PathBuf;

use impactcal::calibrate::report::{
    self, Axis, Block, Figure, Marker, Plot, Report, Section, Structure,
};
use impactcal::calibrate::study::document::{Revealed, reveal_section};
use impactcal::experiment::model::geometry_of;
use impactcal::shell::airframe::{Airframe, AirframeOptions, MeshDensity, Preset};

/// The sensors `impactcal demo` placed on Table 2's study (41, by effective independence).
const SENSORS: [&str; 41] = [
    "69.z", "156.y", "237.y", "245.z", "251.y", "253.y", "303.y", "308.z", "310.z", "318.y",
    "348.y", "399.y", "413.y", "461.y", "464.y", "476.y", "506.y", "541.y", "560.y", "570.y",
    "629.z", "697.z", "879.x", "902.x", "903.x", "910.x", "914.x", "918.x", "921.x", "924.x",
    "934.x", "1068.z", "1072.z", "1181.x", "1195.z", "1215.x", "1228.z", "1231.z", "1261.z",
    "1267.z", "1271.y",
];

/// The channels `impactcal demo --close-loop` compares (the 24 that move most).
const LOOP_CHANNELS: [&str; 24] = [
    "629.z", "245.z", "1231.z", "407.z", "532.z", "1228.z", "502.z", "566.z", "1246.z", "1119.z",
    "1261.z", "732.z", "697.z", "767.z", "1280.z", "1198.z", "1200.z", "468.z", "404.z", "310.z",
    "308.z", "1277.z", "1167.z", "344.z",
];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out: PathBuf = std::env::args()
        .nth(1)
        .ok_or("usage: airframe_report OUT_DIR")?
        .into();
    let airframe = Airframe::new(AirframeOptions::new(MeshDensity::Coarse))?;
    let g = geometry_of(&airframe);
    let marker = |label: &str, value: Option<f64>| -> Result<Marker, String> {
        let at = g
            .channels
            .get(label)
            .copied()
            .ok_or_else(|| format!("the coarse airframe has no channel {label}"))?;
        Ok(Marker {
            label: label.to_string(),
            at,
            value,
        })
    };
    let sensors = SENSORS
        .iter()
        .map(|l| marker(l, None))
        .collect::<Result<Vec<_>, _>>()?;
    // A bending-like pattern of the vertical entries: along the fuselage, sign changing
    // at its middle, as the tail and the floor move against each other.
    let (x0, x1) = g
        .points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p[0]), b.max(p[0]))
        });
    let shape = g
        .channels
        .iter()
        .filter(|(l, _)| l.ends_with(".z"))
        .map(|(_, at)| {
            let s = (at[0] - x0) / (x1 - x0);
            Marker {
                label: String::new(),
                at: *at,
                value: Some((std::f64::consts::PI * s).cos() * 0.08),
            }
        })
        .collect();
    // A signed pattern over the loop's channels, as the residual's u_1 is drawn.
    let residual = LOOP_CHANNELS
        .iter()
        .enumerate()
        .map(|(i, l)| marker(l, Some((0.7 * i as f64).sin() * 0.4)))
        .collect::<Result<Vec<_>, _>>()?;
    let space = Preset::Table2.space()?;
    let hidden = [
        ("belly_panel.t", 1.2, 1.12),
        ("keel_beam_stiffener.t", 1.2, 1.03),
        ("back_panel.t", 0.8, 0.86),
        ("upper_tail.t", 1.0, 1.07),
    ];
    let reveal: Vec<Revealed> = space
        .parameters()
        .iter()
        .map(|p| {
            let (h, c) = hidden
                .iter()
                .find(|(n, _, _)| *n == p.name)
                .map_or((1.0, 1.0), |(_, h, c)| (*h, *c));
            Revealed {
                name: p.name.clone(),
                nominal: p.nominal,
                hidden: h * p.nominal,
                calibrated: c * p.nominal,
            }
        })
        .collect();
    let structure = |marked, value: &str| {
        Plot::Structure(Structure {
            points: g.points.clone(),
            unit: g.unit.clone(),
            marked,
            value_axis: Axis::new(value),
            limit: None,
        })
    };
    let doc = Report {
        title: "The airframe demo's figures on the structure".into(),
        lead: vec![
            "The coarse airframe's mesh with the demo's sensors, an impact shape and the reveal."
                .into(),
        ],
        sections: vec![
            Section {
                heading: "Sensors and an impact shape".into(),
                blocks: vec![
                    Block::Figure(Figure {
                        name: "fig-sensors".into(),
                        caption: "Sensor locations (41 channels)".into(),
                        plot: structure(sensors, "-"),
                    }),
                    Block::Figure(Figure {
                        name: "fig-residual-structure".into(),
                        caption: "A residual pattern over the closed-loop demo's 24 channels"
                            .into(),
                        plot: structure(residual, "u_1 entry (-)"),
                    }),
                    Block::Figure(Figure {
                        name: "fig-shape-1".into(),
                        caption: "A shape's vertical entries at every node".into(),
                        plot: structure(shape, "shape entry (-)"),
                    }),
                ],
            },
            reveal_section(&reveal, 0.05, Some((&g, &space))),
        ],
    };
    let files = report::write(&doc, &out)?;
    // Every sensor keeps its label in at least one of the two views (a label with no free
    // place is thinned from a view, never from both, at the demo's density).
    for (figure, labels) in [
        ("fig-sensors", &SENSORS[..]),
        ("fig-residual-structure", &LOOP_CHANNELS[..]),
    ] {
        let svg = std::fs::read_to_string(out.join(format!("{figure}.svg")))?;
        // The text of each <text> element: what follows its opening tag.
        let shown: Vec<&str> = svg
            .split("</text>")
            .filter_map(|part| part.rsplit_once('>').map(|(_, text)| text.trim()))
            .collect();
        let missing: Vec<&str> = labels
            .iter()
            .copied()
            .filter(|l| !shown.contains(l))
            .collect();
        if !missing.is_empty() {
            // Reported, not yet refused: at the demo's density the placement leaves 318.y
            // without a place in either view (docs/report.md).
            eprintln!(
                "{figure}: {} of {} sensors have a label in neither view: {}",
                missing.len(),
                labels.len(),
                missing.join(", ")
            );
        }
    }
    println!("{}", files.html.display());
    Ok(())
}
