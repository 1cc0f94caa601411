//! The strips' cutting outlines as SVG (1 user unit = 1 mm): each strip's boundary edges (the
//! edges of one of its triangles only), its length and width (bounding box of the aligned,
//! compensated strip) drawn as dimension lines, and its name with its compensation. The strips
//! are stacked down the page, 100 mm apart, `y` up (not mirrored).

use std::collections::HashMap;
use std::fmt::Write;

use super::Strip;
use crate::mech::model::Model;

/// What the outline of one strip says.
#[derive(Clone, Debug, PartialEq)]
pub struct OutlineLabel {
    /// Name shown (e.g. `strip 1`).
    pub name: String,
    /// The compensation `[c_x, c_y]` applied.
    pub compensation: [f64; 2],
}

/// The boundary edges of a strip as pairs of its local node indices.
pub fn boundary_edges(model: &Model, strip: &Strip) -> Vec<[usize; 2]> {
    let index = strip.local_index();
    let mut count: HashMap<[usize; 2], usize> = HashMap::new();
    for &t in &strip.triangles {
        let tri = model.triangles[t].map(|v| index[&v]);
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            *count.entry([a.min(b), a.max(b)]).or_default() += 1;
        }
    }
    let mut edges: Vec<[usize; 2]> = count
        .into_iter()
        .filter(|&(_, n)| n == 1)
        .map(|(e, _)| e)
        .collect();
    edges.sort_unstable();
    edges
}

/// The bounding box `[x0, y0, x1, y1]` of a flat strip (m).
pub fn bounds(flat: &[[f64; 2]]) -> [f64; 4] {
    flat.iter()
        .fold([f64::MAX, f64::MAX, f64::MIN, f64::MIN], |b, p| {
            [
                b[0].min(p[0]),
                b[1].min(p[1]),
                b[2].max(p[0]),
                b[3].max(p[1]),
            ]
        })
}

/// The SVG document of the strips' outlines with their dimensions (mm).
pub fn svg(model: &Model, strips: &[Strip], labels: &[OutlineLabel]) -> String {
    let mm = 1000.0;
    let (mut body, mut top, mut width) = (String::new(), 60.0, 0.0f64);
    for (strip, label) in strips.iter().zip(labels) {
        let [x0, y0, x1, y1] = bounds(&strip.flat).map(|v| v * mm);
        // SVG's y points down: y is mirrored so that the outline is the strip seen from the
        // side its triangles' normals (node order) point to, not its mirror image.
        let (dx, dy) = (40.0 - x0, top + y1);
        let p = |i: usize| (strip.flat[i][0] * mm + dx, dy - strip.flat[i][1] * mm);
        let _ = writeln!(
            body,
            "<g id=\"{}\" fill=\"none\" stroke=\"black\" stroke-width=\"0.5\">",
            label.name.replace(' ', "_")
        );
        for [a, b] in boundary_edges(model, strip) {
            let ((xa, ya), (xb, yb)) = (p(a), p(b));
            let _ = writeln!(
                body,
                "<line x1=\"{xa:.2}\" y1=\"{ya:.2}\" x2=\"{xb:.2}\" y2=\"{yb:.2}\"/>"
            );
        }
        let (l, w) = (x1 - x0, y1 - y0);
        let (bx0, bx1, by0, by1) = (x0 + dx, x1 + dx, dy - y1, dy - y0);
        let _ = writeln!(
            body,
            "<line x1=\"{bx0:.2}\" y1=\"{:.2}\" x2=\"{bx1:.2}\" y2=\"{:.2}\" stroke=\"blue\"/>",
            by1 + 15.0,
            by1 + 15.0
        );
        let _ = writeln!(
            body,
            "<line x1=\"{:.2}\" y1=\"{by0:.2}\" x2=\"{:.2}\" y2=\"{by1:.2}\" stroke=\"blue\"/>",
            bx0 - 15.0,
            bx0 - 15.0
        );
        let _ = writeln!(body, "</g>");
        let text = |x: f64, y: f64, s: String| {
            format!("<text x=\"{x:.2}\" y=\"{y:.2}\" font-size=\"12\">{s}</text>\n")
        };
        body += &text(0.5 * (bx0 + bx1), by1 + 30.0, format!("L = {l:.1} mm"));
        body += &text(bx0 - 35.0, by0 - 5.0, format!("W = {w:.1} mm"));
        body += &text(
            bx0,
            by0 - 20.0,
            format!(
                "{}: compensation {:.3} % × {:.3} %",
                label.name,
                100.0 * label.compensation[0],
                100.0 * label.compensation[1]
            ),
        );
        top = by1 + 100.0;
        width = width.max(bx1 + 40.0);
    }
    format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width:.0}mm\" height=\"{top:.0}mm\" viewBox=\"0 0 {width:.0} {top:.0}\">\n{body}</svg>\n"
    )
}

/// The strips' outlines as a DXF drawing (AutoCAD R12 ASCII, 1 unit = 1 mm, `$INSUNITS` 4), the
/// format cutting plotters read: each strip's boundary edges as `LINE` entities on a layer of
/// its own (`STRIP_<k>`), its length and width as `TEXT` beside it, stacked in `y` 100 mm apart.
pub fn dxf(model: &Model, strips: &[Strip], labels: &[OutlineLabel]) -> String {
    let mm = 1000.0;
    let mut out = String::from("0\nSECTION\n2\nHEADER\n9\n$INSUNITS\n70\n4\n0\nENDSEC\n");
    out += "0\nSECTION\n2\nENTITIES\n";
    let mut base = 0.0;
    for (k, (strip, label)) in strips.iter().zip(labels).enumerate() {
        let [x0, y0, x1, y1] = bounds(&strip.flat).map(|v| v * mm);
        let layer = format!("STRIP_{k}");
        let p = |i: usize| {
            (
                strip.flat[i][0] * mm - x0,
                strip.flat[i][1] * mm - y0 + base,
            )
        };
        for [a, b] in boundary_edges(model, strip) {
            let ((xa, ya), (xb, yb)) = (p(a), p(b));
            let _ = write!(
                out,
                "0\nLINE\n8\n{layer}\n10\n{xa:.3}\n20\n{ya:.3}\n30\n0.0\n11\n{xb:.3}\n21\n{yb:.3}\n31\n0.0\n"
            );
        }
        let text = format!(
            "{}: L = {:.1} mm, W = {:.1} mm, compensation {:.3} % x {:.3} %",
            label.name,
            x1 - x0,
            y1 - y0,
            100.0 * label.compensation[0],
            100.0 * label.compensation[1]
        );
        let _ = write!(
            out,
            "0\nTEXT\n8\n{layer}\n10\n0.0\n20\n{:.3}\n30\n0.0\n40\n12.0\n1\n{text}\n",
            base - 20.0
        );
        base += y1 - y0 + 100.0;
    }
    out + "0\nENDSEC\n0\nEOF\n"
}
