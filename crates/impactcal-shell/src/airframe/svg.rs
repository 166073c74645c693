//! A labelled SVG picture of the airframe's parts, drawn from the mesh itself.

use std::fmt::Write;

use super::{Airframe, AirframePart};

const COLOURS: [&str; 14] = [
    "#e6c229", "#8fbc8f", "#d1495b", "#00798c", "#66a182", "#edae49", "#b0c4de", "#9aa5b1",
    "#8e6c8a", "#f4a259", "#5b8e7d", "#3d5a80", "#c8553d", "#98c1d9",
];

fn colour(p: AirframePart) -> &'static str {
    COLOURS[(p.id() - 1) as usize % COLOURS.len()]
}

/// One view: the direction toward the viewer, the parts left out, whether the near
/// (left-hand, y > 0) skins are cut away, and the panel's title.
struct View {
    toward: [f64; 3],
    omit: &'static [AirframePart],
    cut_near: bool,
    title: &'static str,
}

fn unit(v: [f64; 3]) -> [f64; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / n, v[1] / n, v[2] / n]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(super) fn parts_svg(af: &Airframe) -> String {
    use AirframePart as P;
    let nodes = af.node_positions();
    let views = [
        View {
            toward: [-0.35, 1.0, 0.55],
            omit: &[P::Roof],
            cut_near: true,
            title: "from the left, above and behind: roof and left-hand skins cut away",
        },
        View {
            toward: [0.55, 0.5, 0.8],
            omit: &[
                P::Roof,
                P::SideSkins,
                P::Nose,
                P::CabinFloor,
                P::BackPanel,
                P::EngineFairing,
                P::TailBoom,
                P::UpperTail,
                P::LowerTail,
                P::HorizontalStabilizer,
            ],
            cut_near: false,
            title: "subfloor from the front, left and above: floor and skins removed",
        },
    ];
    // Screen frame of each view: right, up, toward the viewer.
    let frames: Vec<[[f64; 3]; 3]> = views
        .iter()
        .map(|v| {
            let w = unit(v.toward);
            let up0 = if w[2].abs() > 0.99 {
                [-1.0, 0.0, 0.0]
            } else {
                [0.0, 0.0, 1.0]
            };
            let mut r = unit(cross(w, up0));
            if w[2].abs() > 0.99 {
                r = [1.0, 0.0, 0.0];
            }
            let u = cross(r, w);
            [r, u, w]
        })
        .collect();
    let extent = |f: &[[f64; 3]; 3], view: &View| {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for (n, part) in af.shells() {
            if view.omit.contains(&part) {
                continue;
            }
            for &i in &n {
                let p = nodes[i as usize - 1];
                for k in 0..2 {
                    let c = dot(p, f[k]);
                    lo[k] = lo[k].min(c);
                    hi[k] = hi[k].max(c);
                }
            }
        }
        (lo, hi)
    };
    let scale = 3.0;
    let margin = 20.0;
    let legend_w = 230.0;
    let exts: Vec<([f64; 2], [f64; 2])> = frames
        .iter()
        .zip(&views)
        .map(|(f, v)| extent(f, v))
        .collect();
    let width = exts
        .iter()
        .map(|(lo, hi)| (hi[0] - lo[0]) * scale)
        .fold(0.0, f64::max)
        + 2.0 * margin
        + legend_w;
    let heights: Vec<f64> = exts
        .iter()
        .map(|(lo, hi)| (hi[1] - lo[1]) * scale)
        .collect();
    let height = heights.iter().sum::<f64>() + 4.0 * margin + 40.0;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" viewBox="0 0 {width:.0} {height:.0}" font-family="sans-serif" font-size="11">"#
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let mut top = margin + 14.0;
    for (vi, view) in views.iter().enumerate() {
        let h = heights[vi];
        let f = frames[vi];
        let (lo, hi) = exts[vi];
        let _ = writeln!(
            s,
            r#"<text x="{margin}" y="{:.1}" font-size="13" font-weight="bold">{}</text>"#,
            top - 6.0,
            view.title
        );
        let map = |p: [f64; 3]| -> (f64, f64) {
            let x = margin + (dot(p, f[0]) - lo[0]) * scale;
            let y = top + (hi[1] - dot(p, f[1])) * scale;
            (x, y)
        };
        let mut elems: Vec<(f64, [u64; 4], AirframePart)> = af
            .shells()
            .filter(|(n, part)| {
                if view.omit.contains(part) {
                    return false;
                }
                // In the side view, cut away the near (y > 0) skins to show the inside.
                let cut = matches!(part, P::SideSkins | P::Roof | P::Nose | P::EngineFairing);
                if view.cut_near && cut {
                    let yc: f64 = n.iter().map(|&i| nodes[i as usize - 1][1]).sum::<f64>() / 4.0;
                    return yc < 0.0;
                }
                true
            })
            .map(|(n, part)| {
                let d: f64 = n
                    .iter()
                    .map(|&i| dot(nodes[i as usize - 1], f[2]))
                    .sum::<f64>()
                    / 4.0;
                (d, n, part)
            })
            .collect();
        // Painted far to near.
        elems.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (_, n, part) in &elems {
            let mut pts = String::new();
            for &i in n.iter() {
                let (x, y) = map(nodes[i as usize - 1]);
                let _ = write!(pts, "{x:.1},{y:.1} ");
            }
            let _ = writeln!(
                s,
                r##"<polygon points="{}" fill="{}" stroke="#333" stroke-width="0.3"/>"##,
                pts.trim_end(),
                colour(*part)
            );
        }
        // Part labels at the projected centroids of the drawn elements.
        for part in AirframePart::ALL {
            let own: Vec<&(f64, [u64; 4], AirframePart)> =
                elems.iter().filter(|e| e.2 == part).collect();
            if own.is_empty() {
                continue;
            }
            let (mut cx, mut cy) = (0.0, 0.0);
            for e in &own {
                for &i in e.1.iter() {
                    let (x, y) = map(nodes[i as usize - 1]);
                    cx += x;
                    cy += y;
                }
            }
            let k = 4.0 * own.len() as f64;
            let _ = writeln!(
                s,
                r##"<text x="{:.1}" y="{:.1}" text-anchor="middle" stroke="white" stroke-width="3" paint-order="stroke" fill="#111">{}</text>"##,
                cx / k,
                cy / k,
                part.id()
            );
        }
        top += h + 2.0 * margin + 20.0;
    }
    // Legend.
    let lx = width - legend_w + 10.0;
    let _ = writeln!(
        s,
        r#"<text x="{lx}" y="{:.1}" font-size="13" font-weight="bold">parts</text>"#,
        margin + 8.0
    );
    for (k, part) in AirframePart::ALL.iter().enumerate() {
        let y = margin + 22.0 + 18.0 * k as f64;
        let _ = writeln!(
            s,
            r##"<rect x="{lx}" y="{:.1}" width="14" height="12" fill="{}" stroke="#333" stroke-width="0.5"/><text x="{:.1}" y="{:.1}">{} {}</text>"##,
            y - 10.0,
            colour(*part),
            lx + 20.0,
            y,
            part.id(),
            part.name()
        );
    }
    let _ = writeln!(
        s,
        r#"<text x="{lx}" y="{:.1}">{} shells, {} nodes, {} sensors</text>"#,
        margin + 22.0 + 18.0 * 15.0,
        af.shell_count(),
        af.node_count(),
        af.sensor_nodes().len()
    );
    s.push_str("</svg>\n");
    s
}
