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

/// One view: which coordinates go right and up, which parts are left out, the depth axis
/// (elements are painted far to near) and the panel's title.
struct View {
    right: usize,
    up: usize,
    depth: usize,
    flip_up: bool,
    omit: &'static [AirframePart],
    title: &'static str,
}

pub(super) fn parts_svg(af: &Airframe) -> String {
    use AirframePart as P;
    let nodes = af.node_positions();
    let views = [
        View {
            right: 0,
            up: 2,
            depth: 1,
            flip_up: false,
            omit: &[],
            title: "side view (left-hand skins, roof and nose cut away)",
        },
        View {
            right: 0,
            up: 1,
            depth: 2,
            flip_up: false,
            omit: &[
                P::Roof,
                P::SideSkins,
                P::Nose,
                P::EngineFairing,
                P::BackPanel,
            ],
            title: "plan view (skins, roof, nose, fairing and back panel removed)",
        },
    ];
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in nodes {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let scale = 3.0;
    let margin = 20.0;
    let legend_w = 230.0;
    let width = (hi[0] - lo[0]) * scale + 2.0 * margin + legend_w;
    let heights = [(hi[2] - lo[2]) * scale, (hi[1] - lo[1]) * scale];
    let height = heights[0] + heights[1] + 4.0 * margin + 40.0;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" viewBox="0 0 {width:.0} {height:.0}" font-family="sans-serif" font-size="11">"#
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let mut top = margin + 14.0;
    for (vi, view) in views.iter().enumerate() {
        let h = heights[vi];
        let _ = writeln!(
            s,
            r#"<text x="{margin}" y="{:.1}" font-size="13" font-weight="bold">{}</text>"#,
            top - 6.0,
            view.title
        );
        let map = |p: [f64; 3]| -> (f64, f64) {
            let x = margin + (p[view.right] - lo[view.right]) * scale;
            let v = (p[view.up] - lo[view.up]) * scale;
            let y = if view.flip_up { top + v } else { top + h - v };
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
                if vi == 0 && cut {
                    let yc: f64 = n.iter().map(|&i| nodes[i as usize - 1][1]).sum::<f64>() / 4.0;
                    return yc < 0.0;
                }
                true
            })
            .map(|(n, part)| {
                let d: f64 = n
                    .iter()
                    .map(|&i| nodes[i as usize - 1][view.depth])
                    .sum::<f64>()
                    / 4.0;
                (d, n, part)
            })
            .collect();
        // Far to near: the viewer looks from +y (side) and from +z (plan).
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
