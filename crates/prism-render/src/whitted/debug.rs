//! A pixel's ray tree written out: the debug JSON (`{"pixel", "color", "rays": [...]}`)
//! and an ASCII PLY of coloured line segments that Blender imports.

use std::fmt::Write;

use prism_math::{Rgb, Vec3};

use super::film::PixelTrace;
use super::scene::Surface;
use super::tracer::DebugRay;

/// A number as JSON: the shortest round-trip decimal, `null` if not finite.
fn num(out: &mut String, x: f32) {
    if x.is_finite() {
        out.push_str(ryu::Buffer::new().format(x));
    } else {
        out.push_str("null");
    }
}

fn vec(out: &mut String, v: [f32; 3]) {
    out.push('[');
    for (i, x) in v.iter().enumerate() {
        if i > 0 {
            out.push(',');
        }
        num(out, *x);
    }
    out.push(']');
}

fn rgb(c: Rgb) -> [f32; 3] {
    [c.r, c.g, c.b]
}

fn v3(v: Vec3) -> [f32; 3] {
    v.to_array()
}

/// A JSON string literal.
fn string(out: &mut String, s: &str) {
    out.push('"');
    for ch in s.chars() {
        match ch {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
}

fn ray_json(out: &mut String, r: &DebugRay) {
    out.push_str("{\"kind\":");
    string(out, r.kind.name());
    let _ = write!(out, ",\"depth\":{}", r.depth);
    out.push_str(",\"origin\":");
    vec(out, v3(r.origin));
    out.push_str(",\"end\":");
    vec(out, v3(r.end));
    out.push_str(",\"color\":");
    vec(out, rgb(r.color));
    out.push_str(",\"blocked\":");
    match r.blocked {
        Some(b) => out.push_str(if b { "true" } else { "false" }),
        None => out.push_str("null"),
    }
    if let Some(p) = r.blocked_at {
        out.push_str(",\"blocked_at\":");
        vec(out, v3(p));
    }
    if let Some(t) = r.time {
        out.push_str(",\"time\":");
        num(out, t);
    }
    out.push_str(",\"hit\":");
    match &r.hit {
        None => out.push_str("null"),
        Some((material, surface)) => {
            out.push_str("{\"material\":");
            string(out, material);
            let _ = match surface {
                Surface::Triangle(i) => write!(out, ",\"triangle\":{i}}}"),
                Surface::Sphere(i) => write!(out, ",\"sphere\":{i}}}"),
            };
        }
    }
    out.push('}');
}

impl PixelTrace {
    /// The debug JSON: `{"pixel":[x,y],"color":[r,g,b],"rays":[{"kind","depth","origin",
    /// "end","color","blocked","hit"}, ...]}`, one ray per line.
    #[must_use]
    pub fn to_json(&self) -> String {
        let mut out = String::new();
        let _ = write!(
            out,
            "{{\"pixel\":[{},{}],\"color\":",
            self.pixel.0, self.pixel.1
        );
        vec(&mut out, rgb(self.color));
        out.push_str(",\"rays\":[");
        for (i, r) in self.rays.iter().enumerate() {
            out.push_str(if i == 0 { "\n" } else { ",\n" });
            ray_json(&mut out, r);
        }
        out.push_str("\n]}\n");
        out
    }

    /// The rays as an ASCII PLY of line segments: two coloured vertices and one edge each
    /// (colours clamped to [0, 1] and stored as bytes).
    #[must_use]
    pub fn to_ply(&self) -> String {
        let mut out = String::new();
        let n = self.rays.len();
        let _ = write!(
            out,
            "ply\nformat ascii 1.0\ncomment prism ray tree of pixel {} {}\nelement vertex {}\n\
             property float x\nproperty float y\nproperty float z\nproperty uchar red\n\
             property uchar green\nproperty uchar blue\nelement edge {n}\nproperty int vertex1\n\
             property int vertex2\nend_header\n",
            self.pixel.0,
            self.pixel.1,
            2 * n
        );
        let byte = |x: f32| (x.clamp(0.0, 1.0) * 255.0) as u8;
        for r in &self.rays {
            for p in [r.origin, r.end] {
                let c = r.color;
                let _ = writeln!(
                    out,
                    "{} {} {} {} {} {}",
                    p.x,
                    p.y,
                    p.z,
                    byte(c.r),
                    byte(c.g),
                    byte(c.b)
                );
            }
        }
        for i in 0..n {
            let _ = writeln!(out, "{} {}", 2 * i, 2 * i + 1);
        }
        out
    }
}
