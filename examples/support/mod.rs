//! Shared software rendering for the demo pictures (`examples/render_*.rs`), no GPU: a tiny-skia canvas,
//! panels that look through a [`StrokeCamera`] (the library's own projection), a shaded head with eyes, chains
//! as thick lines with round joints drawn back to front, a 5x7 bitmap font, PNG and GIF output.

#![allow(dead_code)]

use std::path::Path;

use glam::{Vec2, Vec3};
use kodawari::Transform;
use kodawari::core::sketch::StrokeCamera;
use tiny_skia::{
    Color, FillRule, GradientStop, LineCap, LineJoin, Paint, PathBuilder, Pixmap, Point, RadialGradient, Rect,
    SpreadMode, Stroke,
};

pub fn rgb(r: u8, g: u8, b: u8) -> Color {
    Color::from_rgba8(r, g, b, 255)
}

pub const BACKGROUND: (u8, u8, u8) = (214, 223, 238);
pub const SKIN: (u8, u8, u8) = (247, 214, 190);
pub const EYE: (u8, u8, u8) = (40, 36, 52);
pub const INK: (u8, u8, u8) = (48, 52, 64);
pub const GREY: (u8, u8, u8) = (128, 134, 148);

pub fn color((r, g, b): (u8, u8, u8)) -> Color {
    rgb(r, g, b)
}

/// An RGBA picture to draw on.
pub struct Canvas {
    pub pixmap: Pixmap,
}

fn paint(color: Color) -> Paint<'static> {
    let mut paint = Paint { anti_alias: true, ..Paint::default() };
    paint.set_color(color);
    paint
}

impl Canvas {
    pub fn new(width: u32, height: u32) -> Self {
        let mut pixmap = Pixmap::new(width, height).expect("non-zero size");
        pixmap.fill(color(BACKGROUND));
        Self { pixmap }
    }

    pub fn width(&self) -> u32 {
        self.pixmap.width()
    }

    pub fn height(&self) -> u32 {
        self.pixmap.height()
    }

    pub fn rect(&mut self, x: f32, y: f32, w: f32, h: f32, color: Color) {
        if let Some(rect) = Rect::from_xywh(x, y, w, h) {
            self.pixmap.fill_rect(rect, &paint(color), tiny_skia::Transform::identity(), None);
        }
    }

    pub fn circle(&mut self, centre: Vec2, radius: f32, color: Color) {
        if let Some(path) = PathBuilder::from_circle(centre.x, centre.y, radius.max(0.1)) {
            self.pixmap.fill_path(&path, &paint(color), FillRule::Winding, tiny_skia::Transform::identity(), None);
        }
    }

    /// A circle lit from `light` (an offset in units of the radius): bright there, darker at the rim.
    pub fn shaded_circle(&mut self, centre: Vec2, radius: f32, light: Vec2, bright: Color, dark: Color) {
        let Some(path) = PathBuilder::from_circle(centre.x, centre.y, radius.max(0.1)) else { return };
        let focus = centre + light * radius;
        let shader = RadialGradient::new(
            Point::from_xy(focus.x, focus.y),
            0.0,
            Point::from_xy(centre.x, centre.y),
            radius * 1.05,
            vec![GradientStop::new(0.0, bright), GradientStop::new(1.0, dark)],
            SpreadMode::Pad,
            tiny_skia::Transform::identity(),
        );
        let mut paint = Paint { anti_alias: true, ..Paint::default() };
        match shader {
            Some(shader) => paint.shader = shader,
            None => paint.set_color(bright),
        }
        self.pixmap.fill_path(&path, &paint, FillRule::Winding, tiny_skia::Transform::identity(), None);
    }

    /// A filled polygon.
    pub fn polygon(&mut self, points: &[Vec2], color: Color) {
        let mut builder = PathBuilder::new();
        for (i, p) in points.iter().enumerate() {
            if i == 0 { builder.move_to(p.x, p.y) } else { builder.line_to(p.x, p.y) }
        }
        builder.close();
        if let Some(path) = builder.finish() {
            self.pixmap.fill_path(&path, &paint(color), FillRule::Winding, tiny_skia::Transform::identity(), None);
        }
    }

    /// A polyline `width` pixels wide with round caps and joins.
    pub fn polyline(&mut self, points: &[Vec2], width: f32, color: Color) {
        if points.len() < 2 {
            return;
        }
        let mut builder = PathBuilder::new();
        builder.move_to(points[0].x, points[0].y);
        for p in &points[1..] {
            builder.line_to(p.x, p.y);
        }
        let Some(path) = builder.finish() else { return };
        let stroke = Stroke { width, line_cap: LineCap::Round, line_join: LineJoin::Round, ..Stroke::default() };
        self.pixmap.stroke_path(&path, &paint(color), &stroke, tiny_skia::Transform::identity(), None);
    }

    pub fn line(&mut self, a: Vec2, b: Vec2, width: f32, color: Color) {
        self.polyline(&[a, b], width, color);
    }

    /// A dashed polyline (dash and gap in pixels).
    pub fn dashed(&mut self, points: &[Vec2], width: f32, dash: f32, gap: f32, color: Color) {
        let mut on = true;
        let mut left = dash;
        let mut piece = vec![points[0]];
        for w in points.windows(2) {
            let (mut a, b) = (w[0], w[1]);
            while a.distance(b) > 0.0 {
                let step = left.min(a.distance(b));
                let next = a + (b - a).normalize() * step;
                if on {
                    piece.push(next);
                }
                left -= step;
                a = next;
                if left <= 1e-3 {
                    if on {
                        self.polyline(&piece, width, color);
                    }
                    on = !on;
                    left = if on { dash } else { gap };
                    piece = vec![a];
                }
            }
        }
        if on {
            self.polyline(&piece, width, color);
        }
    }

    /// Text in the built-in 5x7 font (upper case; unknown characters are blank), top-left at `(x, y)`, each
    /// font pixel `scale` pixels. Returns the width drawn.
    pub fn text(&mut self, x: f32, y: f32, scale: f32, text: &str, color: Color) -> f32 {
        let mut pen = x;
        for c in text.chars() {
            if let Some(rows) = glyph(c.to_ascii_uppercase()) {
                for (r, row) in rows.chunks(5).enumerate() {
                    for (k, bit) in row.iter().enumerate() {
                        if *bit == b'#' {
                            self.rect(pen + k as f32 * scale, y + r as f32 * scale, scale, scale, color);
                        }
                    }
                }
            }
            pen += 6.0 * scale;
        }
        pen - x - scale
    }

    /// Text centred on `cx`.
    pub fn text_centred(&mut self, cx: f32, y: f32, scale: f32, text: &str, color: Color) {
        let width = text_width(text, scale);
        self.text(cx - 0.5 * width, y, scale, text, color);
    }

    /// Copies `other` with its top-left corner at `(x, y)`.
    pub fn paste(&mut self, other: &Canvas, x: i32, y: i32) {
        self.pixmap.draw_pixmap(
            x,
            y,
            other.pixmap.as_ref(),
            &tiny_skia::PixmapPaint::default(),
            tiny_skia::Transform::identity(),
            None,
        );
    }

    /// Straight RGBA bytes (the canvas is opaque, so premultiplied = straight).
    pub fn rgba(&self) -> Vec<u8> {
        self.pixmap.data().to_vec()
    }

    pub fn save_png(&self, path: &Path) -> Result<(), Box<dyn std::error::Error>> {
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir)?;
        }
        self.pixmap.save_png(path)?;
        Ok(())
    }
}

pub fn text_width(text: &str, scale: f32) -> f32 {
    text.chars().count() as f32 * 6.0 * scale - scale
}

/// Writes an endlessly looping GIF of RGBA frames, `delay` hundredths of a second each.
pub fn save_gif(
    path: &Path,
    width: u32,
    height: u32,
    frames: &[Vec<u8>],
    delay: u16,
) -> Result<(), Box<dyn std::error::Error>> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let file = std::io::BufWriter::new(std::fs::File::create(path)?);
    let mut encoder = gif::Encoder::new(file, width as u16, height as u16, &[])?;
    encoder.set_repeat(gif::Repeat::Infinite)?;
    for rgba in frames {
        let mut pixels = rgba.clone();
        let mut frame = gif::Frame::from_rgba_speed(width as u16, height as u16, &mut pixels, 10);
        frame.delay = delay;
        encoder.write_frame(&frame)?;
    }
    Ok(())
}

/// A region of a canvas seen through a camera whose viewport is the region's size.
pub struct Panel {
    pub camera: StrokeCamera,
    /// Top-left corner of the region in the canvas.
    pub origin: Vec2,
}

impl Panel {
    pub fn project(&self, p: Vec3) -> Option<Vec2> {
        self.camera.project(p).map(|pixel| pixel + self.origin)
    }

    /// Distance in front of the camera.
    pub fn depth(&self, p: Vec3) -> f32 {
        (p - self.camera.position).dot(self.camera.forward())
    }

    /// Pixels per metre for something at `p`, face-on.
    pub fn scale_at(&self, p: Vec3) -> f32 {
        let right = self.camera.rotation * Vec3::X;
        match (self.project(p), self.project(p + right * 0.01)) {
            (Some(a), Some(b)) => a.distance(b) / 0.01,
            _ => 0.0,
        }
    }

    /// Unit direction from `p` towards the eye.
    pub fn to_eye(&self, p: Vec3) -> Vec3 {
        match self.camera.projection {
            kodawari::core::sketch::Projection::Perspective { .. } => (self.camera.position - p).normalize(),
            kodawari::core::sketch::Projection::Orthographic { .. } => -self.camera.forward(),
        }
    }
}

/// How to draw one chain.
#[derive(Clone, Copy)]
pub struct ChainStyle {
    pub color: Color,
    /// Line width in metres (scaled by the perspective).
    pub width: f32,
    /// Joint dots: colour and diameter in metres.
    pub joint: Color,
    pub joint_size: f32,
    /// An inner stripe (colour, width as a fraction of the line's), e.g. the inside of a rabbit ear.
    pub stripe: Option<(Color, f32)>,
}

/// A head: a sphere of `radius` around the transform's position, facing its local +z, with two eyes.
pub struct Head {
    pub pose: Transform,
    pub radius: f32,
}

enum Item<'a> {
    Head,
    Segment { chain: &'a [Vec3], index: usize, style: ChainStyle },
}

/// Draws a head and chains (world joint positions) back to front through `panel`.
pub fn draw_scene(canvas: &mut Canvas, panel: &Panel, head: Option<&Head>, chains: &[(Vec<Vec3>, ChainStyle)]) {
    let mut items: Vec<(f32, Item)> = Vec::new();
    if let Some(head) = head {
        items.push((panel.depth(head.pose.position), Item::Head));
    }
    for (points, style) in chains {
        for index in 0..points.len().saturating_sub(1) {
            let depth = panel.depth(0.5 * (points[index] + points[index + 1]));
            items.push((depth, Item::Segment { chain: points, index, style: *style }));
        }
    }
    items.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (_, item) in items {
        match item {
            Item::Head => draw_head(canvas, panel, head.expect("has a head")),
            Item::Segment { chain, index, style } => {
                let (a, b) = (chain[index], chain[index + 1]);
                let (Some(pa), Some(pb)) = (panel.project(a), panel.project(b)) else { continue };
                let width = style.width * panel.scale_at(0.5 * (a + b));
                canvas.line(pa, pb, width.max(1.0), style.color);
                if let Some((stripe, fraction)) = style.stripe {
                    canvas.line(pa, pb, (width * fraction).max(1.0), stripe);
                }
                for (p, at) in [(pa, a), (pb, b)] {
                    canvas.circle(p, 0.5 * style.joint_size * panel.scale_at(at), style.joint);
                }
            }
        }
    }
}

fn draw_head(canvas: &mut Canvas, panel: &Panel, head: &Head) {
    let centre = head.pose.position;
    let Some(c) = panel.project(centre) else { return };
    let radius = head.radius * panel.scale_at(centre);
    // Lit from the camera's upper left.
    let light = Vec2::new(-0.35, -0.4);
    canvas.shaded_circle(c, radius, light, rgb(255, 236, 222), rgb(214, 160, 132));
    // Eyes: ellipses on the sphere, as seen (foreshortened), only on the visible side.
    for side in [-1.0f32, 1.0] {
        let local = Vec3::new(side * 0.38, 0.08, 0.0);
        let local = Vec3::new(local.x, local.y, (1.0 - local.x * local.x - local.y * local.y).sqrt());
        let normal = head.pose.rotation * local;
        let facing = normal.dot(panel.to_eye(centre + normal * head.radius));
        if facing <= 0.05 {
            continue;
        }
        let at = centre + normal * head.radius;
        let u = (head.pose.rotation * Vec3::X - normal * normal.dot(head.pose.rotation * Vec3::X)).normalize();
        let v = normal.cross(u);
        let (rx, ry) = (0.11 * head.radius, 0.17 * head.radius);
        let outline: Vec<Vec2> = (0..24)
            .filter_map(|k| {
                let t = k as f32 / 24.0 * std::f32::consts::TAU;
                panel.project(at + u * (rx * t.cos()) + v * (ry * t.sin()))
            })
            .collect();
        if outline.len() == 24 {
            canvas.polygon(&outline, color(EYE));
        }
    }
    // A small mouth, also only when facing.
    let mouth = head.pose.rotation * Vec3::new(0.0, -0.42, 0.907).normalize();
    if mouth.dot(panel.to_eye(centre + mouth * head.radius)) > 0.05 {
        let points: Vec<Vec2> = (0..=8)
            .filter_map(|k| {
                let s = (k as f32 / 8.0 - 0.5) * 0.45;
                let local = Vec3::new(s, -0.42 - 0.25 * (0.2025 - 4.0 * s * s * 0.2025).max(0.0).sqrt(), 0.0);
                let local = Vec3::new(local.x, local.y, (1.0 - local.x * local.x - local.y * local.y).max(0.0).sqrt());
                panel.project(centre + head.pose.rotation * local * head.radius)
            })
            .collect();
        canvas.polyline(&points, (0.04 * radius).max(1.0), rgb(170, 90, 90));
    }
}

/// The 5x7 glyph of `c` as 35 bytes, `#` for ink, row by row.
fn glyph(c: char) -> Option<&'static [u8]> {
    let rows: &str = match c {
        'A' => ".###.#...##...#######...##...##...#",
        'B' => "####.#...##...#####.#...##...#####.",
        'C' => ".###.#...##....#....#....#...#.###.",
        'D' => "####.#...##...##...##...##...#####.",
        'E' => "######....#....####.#....#....#####",
        'F' => "######....#....####.#....#....#....",
        'G' => ".###.#...##....#.####...##...#.###.",
        'H' => "#...##...##...#######...##...##...#",
        'I' => ".###...#....#....#....#....#...###.",
        'J' => "..###...#....#....#....#.#..#..##..",
        'K' => "#...##..#.#.#..##...#.#..#..#.#...#",
        'L' => "#....#....#....#....#....#....#####",
        'M' => "#...###.###.#.##.#.##...##...##...#",
        'N' => "#...##...###..##.#.##..###...##...#",
        'O' => ".###.#...##...##...##...##...#.###.",
        'P' => "####.#...##...#####.#....#....#....",
        'Q' => ".###.#...##...##...##.#.##..#..##.#",
        'R' => "####.#...##...#####.#.#..#..#.#...#",
        'S' => ".#####....#.....###.....#....#####.",
        'T' => "#####..#....#....#....#....#....#..",
        'U' => "#...##...##...##...##...##...#.###.",
        'V' => "#...##...##...##...#.#.#..#.#...#..",
        'W' => "#...##...##...##.#.##.#.###.###...#",
        'X' => "#...##...#.#.#...#...#.#.#...##...#",
        'Y' => "#...##...#.#.#...#....#....#....#..",
        'Z' => "#####....#...#...#...#...#....#####",
        '0' => ".###.#...##..###.#.###..##...#.###.",
        '1' => "..#...##....#....#....#....#...###.",
        '2' => ".###.#...#....#...#...#...#...#####",
        '3' => "#####...#...#.....#.....##...#.###.",
        '4' => "...#...##..#.#.#..#.#####...#....#.",
        '5' => "######....####.....#....##...#.###.",
        '6' => "..##..#...#....####.#...##...#.###.",
        '7' => "#####....#...#...#...#....#....#...",
        '8' => ".###.#...##...#.###.#...##...#.###.",
        '9' => ".###.#...##...#.####....#...#..##..",
        '°' => ".##..#..#.#..#..##.................",
        ':' => ".....##...##........##...##........",
        '-' => "...............#####...............",
        '.' => ".........................##...##...",
        '/' => "....#....#...#...#...#...#....#....",
        '(' => "...#...#...#....#....#.....#.....#.",
        ')' => ".#.....#.....#....#....#...#...#...",
        ',' => "....................##....#...#....",
        '+' => "......#....#..#####..#....#........",
        '=' => "..........#####.....#####..........",
        ' ' => return Some(b"..................................."),
        _ => return None,
    };
    debug_assert_eq!(rows.len(), 35, "glyph {c}");
    Some(rows.as_bytes())
}
