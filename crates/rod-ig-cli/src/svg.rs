//! SVG pictures of rods: a picture says at a glance what a JSON array of poses does not.

use rod_ig_core::PlanarPose;
use std::fmt::Write;

/// One rod to draw, with a caption.
pub struct DrawnRod {
    /// Sampled poses from base to tip.
    pub poses: Vec<PlanarPose>,
    /// Legend text.
    pub label: String,
    /// Drawn dashed (e.g. an unstable equilibrium).
    pub dashed: bool,
    /// Drawn thin and grey, behind the others (e.g. the weightless rods beside heavy ones).
    pub muted: bool,
}

/// The colour of muted rods.
const MUTED: &str = "#aaaaaa";

impl DrawnRod {
    /// Colour and width of the `i`-th rod's line.
    fn stroke(&self, i: usize) -> (&'static str, f64) {
        if self.muted {
            (MUTED, 1.5)
        } else {
            (COLOURS[i % COLOURS.len()], 3.0)
        }
    }
}

const COLOURS: [&str; 6] = [
    "#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf",
];

/// Draws the rods in the base frame (x right, y up: REP 103), with the reachable disc
/// ‖(x, y)‖ ≤ 1 of the unit rod, the base gripper at the origin and each tip's tangent.
pub fn draw(rods: &[DrawnRod], title: &str) -> String {
    let size = 640.0;
    let margin = 40.0;
    // World window [-1.1, 1.1]²: the unit rod never leaves the unit disc.
    let scale = (size - 2.0 * margin) / 2.2;
    let px = |x: f64| margin + (x + 1.1) * scale;
    let py = |y: f64| margin + (1.1 - y) * scale;
    let h = size + 30.0 + 18.0 * rods.len() as f64;
    let mut s = open(size, h, margin, title, (px(0.0), py(0.0), scale));
    let _ = write!(
        s,
        r##"<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="#999"/><line x1="{}" y1="{}" x2="{}" y2="{}" stroke="#999"/>"##,
        px(-1.1),
        py(0.0),
        px(1.1),
        py(0.0),
        px(0.0),
        py(-1.1),
        px(0.0),
        py(1.1)
    );
    // Base gripper: a small block behind the origin, facing +x.
    let _ = write!(
        s,
        r##"<rect x="{}" y="{}" width="{}" height="{}" fill="#555"/>"##,
        px(-0.06),
        py(0.03),
        0.06 * scale,
        0.06 * scale
    );
    for (i, rod) in rods.iter().enumerate() {
        let (colour, width) = rod.stroke(i);
        let points: Vec<String> = rod
            .poses
            .iter()
            .filter(|p| p.is_finite())
            .map(|p| format!("{:.2},{:.2}", px(p.x), py(p.y)))
            .collect();
        let dash = if rod.dashed {
            r#" stroke-dasharray="8 5""#
        } else {
            ""
        };
        let _ = write!(
            s,
            r#"<polyline points="{}" fill="none" stroke="{colour}" stroke-width="{width}"{dash}/>"#,
            points.join(" ")
        );
        if let Some(tip) = rod.poses.last().filter(|p| p.is_finite()) {
            let (dx, dy) = (tip.theta.cos() * 0.08, tip.theta.sin() * 0.08);
            let _ = write!(
                s,
                r#"<circle cx="{:.2}" cy="{:.2}" r="5" fill="{colour}"/><line x1="{:.2}" y1="{:.2}" x2="{:.2}" y2="{:.2}" stroke="{colour}" stroke-width="5"/>"#,
                px(tip.x),
                py(tip.y),
                px(tip.x - dx),
                py(tip.y - dy),
                px(tip.x + dx),
                py(tip.y + dy)
            );
        }
        let y = size + 18.0 * (i as f64 + 1.0);
        let _ = write!(
            s,
            r#"<line x1="{margin}" y1="{}" x2="{}" y2="{}" stroke="{colour}" stroke-width="3"{dash}/><text x="{}" y="{}">{}</text>"#,
            y - 4.0,
            margin + 30.0,
            y - 4.0,
            margin + 38.0,
            y,
            escape(&rod.label)
        );
    }
    s.push_str("</svg>\n");
    s
}

/// What a rod of a sequence (`track`, `plan`) is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SequenceKind {
    /// The rod held at the start.
    Start,
    /// A rod along the motion.
    Step,
    /// The last stable rod of a branch that folded (snap-through starts here).
    Critical,
    /// The rod a snap settled into.
    Snapped,
}

/// One rod of a motion.
#[derive(Clone, Debug)]
pub struct SequenceRod {
    /// Sampled poses, base to tip.
    pub poses: Vec<PlanarPose>,
    /// Its role.
    pub kind: SequenceKind,
}

/// An obstacle to draw.
#[derive(Clone, Debug)]
pub enum Obstacle {
    /// Centre and radius.
    Disc([f64; 2], f64),
    /// Vertices.
    Polygon(Vec<[f64; 2]>),
}

impl From<&rod_ig_core::plan::Obstacle> for Obstacle {
    fn from(o: &rod_ig_core::plan::Obstacle) -> Self {
        match o {
            rod_ig_core::plan::Obstacle::Disc { center, radius } => Self::Disc(*center, *radius),
            rod_ig_core::plan::Obstacle::Polygon { points } => Self::Polygon(points.clone()),
        }
    }
}

/// Draws a motion: rods from light to dark blue in order, the start in black, critical rods
/// (where a branch folded) dashed red, the rod each snap settled into solid red, the
/// gripper's path through the tips, and the obstacles in grey.
pub fn draw_sequence(rods: &[SequenceRod], obstacles: &[Obstacle], title: &str) -> String {
    let size = 640.0;
    let margin = 40.0;
    let scale = (size - 2.0 * margin) / 2.2;
    let px = |x: f64| margin + (x + 1.1) * scale;
    let py = |y: f64| margin + (1.1 - y) * scale;
    let h = size + 30.0;
    let mut s = open(size, h, margin, title, (px(0.0), py(0.0), scale));
    for o in obstacles {
        match o {
            Obstacle::Disc(c, r) => {
                let _ = write!(
                    s,
                    r##"<circle cx="{:.2}" cy="{:.2}" r="{:.2}" fill="#999"/>"##,
                    px(c[0]),
                    py(c[1]),
                    r * scale
                );
            }
            Obstacle::Polygon(points) => {
                let pts: Vec<String> = points
                    .iter()
                    .map(|p| format!("{:.2},{:.2}", px(p[0]), py(p[1])))
                    .collect();
                let _ = write!(s, r##"<polygon points="{}" fill="#999"/>"##, pts.join(" "));
            }
        }
    }
    let polyline = |poses: &[PlanarPose]| -> String {
        poses
            .iter()
            .filter(|p| p.is_finite())
            .map(|p| format!("{:.2},{:.2}", px(p.x), py(p.y)))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let steps = rods.len().max(2) as f64;
    let mut tips = Vec::new();
    for (i, rod) in rods.iter().enumerate() {
        let (colour, width, dash) = match rod.kind {
            SequenceKind::Start => ("#000".to_string(), 2.5, ""),
            SequenceKind::Step => {
                // Light to dark blue along the motion.
                let f = i as f64 / (steps - 1.0);
                let light = (200.0 - 150.0 * f) as u8;
                (format!("rgb({light},{light},255)"), 1.2, "")
            }
            SequenceKind::Critical => ("#d62728".to_string(), 2.5, r#" stroke-dasharray="7 4""#),
            SequenceKind::Snapped => ("#d62728".to_string(), 2.5, ""),
        };
        let _ = write!(
            s,
            r#"<polyline points="{}" fill="none" stroke="{colour}" stroke-width="{width}"{dash}/>"#,
            polyline(&rod.poses)
        );
        if let Some(t) = rod.poses.last().filter(|p| p.is_finite()) {
            tips.push(*t);
        }
    }
    let _ = write!(
        s,
        r##"<polyline points="{}" fill="none" stroke="#2ca02c" stroke-width="1.5"/>"##,
        polyline(&tips)
    );
    let legend = "black: start · blue: rods along the motion · green: gripper path ·                   red dashed: critical rod · red: after the snap";
    let _ = write!(
        s,
        r#"<text x="{margin}" y="{}" font-size="12">{}</text>"#,
        size + 14.0,
        escape(legend)
    );
    s.push_str("</svg>\n");
    s
}

/// The picture's opening: canvas, white background, title and the reachable disc ‖(x, y)‖ ≤ 1
/// of the unit rod (`disc`: centre in pixels and radius).
fn open(size: f64, h: f64, margin: f64, title: &str, disc: (f64, f64, f64)) -> String {
    let mut s = String::new();
    let _ = write!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{size}" height="{h}" viewBox="0 0 {size} {h}" font-family="sans-serif" font-size="13">"#
    );
    let _ = write!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = write!(
        s,
        r#"<text x="{margin}" y="24" font-size="15">{}</text>"#,
        escape(title)
    );
    let (cx, cy, r) = disc;
    let _ = write!(
        s,
        r##"<circle cx="{cx}" cy="{cy}" r="{r}" fill="#f4f4f4" stroke="#bbb" stroke-dasharray="4 4"/>"##
    );
    s
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_one_polyline_per_rod_and_escapes_labels() {
        let rod = |label: &str| DrawnRod {
            muted: false,
            poses: vec![
                PlanarPose::new(0.0, 0.0, 0.0),
                PlanarPose::new(1.0, 0.0, 0.0),
            ],
            label: label.to_string(),
            dashed: false,
        };
        let svg = draw(&[rod("a<b"), rod("c")], "t & t");
        assert_eq!(svg.matches("<polyline").count(), 2);
        assert!(svg.contains("a&lt;b") && svg.contains("t &amp; t"));
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>\n"));
    }

    #[test]
    fn non_finite_poses_are_skipped() {
        let rod = DrawnRod {
            muted: false,
            poses: vec![
                PlanarPose::new(0.0, 0.0, 0.0),
                PlanarPose::new(f64::NAN, 0.0, 0.0),
            ],
            label: String::new(),
            dashed: true,
        };
        assert!(!draw(&[rod], "").contains("NaN"));
    }
}
