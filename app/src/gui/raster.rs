//! A small depth-buffered rasteriser for the viewport: shaded triangles, depth-tested lines and
//! points, drawn on the CPU into an RGBA image that egui shows as a texture.
//!
//! Why on the CPU: the machines hox is taught and tested on have no GPU (a software GL or
//! Vulkan driver would rasterise on the CPU anyway), the picture is then identical in the window,
//! in headless tests and in screenshots, and the cost is measured (docs/APP.md). Rows are cut
//! into bands rasterised in parallel (rayon).
//!
//! Conventions: right-handed world, `z` up; a perspective camera orbiting a target. Triangles
//! are projected to normalised device coordinates and rasterised with edge functions; depth
//! `z_ndc` is interpolated linearly in screen space (exact for a perspective projection), colour
//! with screen-space barycentrics (Gouraud, Lambert shading with a head light, both sides lit).

use glam::{Mat4, Vec3, Vec4};
use rayon::prelude::*;

/// An orbiting perspective camera.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Camera {
    pub target: [f32; 3],
    pub distance: f32,
    /// Rotation about the world z axis, radians.
    pub yaw: f32,
    /// Elevation above the x–y plane, radians.
    pub pitch: f32,
    /// Vertical field of view, radians.
    pub fov_y: f32,
}

/// The view's width over its height assumed before it is first drawn.
pub const DEFAULT_ASPECT: f32 = 1.3;

impl Camera {
    /// A three-quarter view that frames the box `[lo, hi]`.
    pub fn framing(lo: [f32; 3], hi: [f32; 3]) -> Camera {
        Camera::framing_from(lo, hi, -1.2, 0.45, DEFAULT_ASPECT)
    }

    /// A view from the direction `(yaw, pitch)` that frames the box `[lo, hi]`: its extent
    /// across the line of sight fills about 60 % of a view `aspect` times as wide as high (room
    /// for a beam to bend and swing).
    pub fn framing_from(lo: [f32; 3], hi: [f32; 3], yaw: f32, pitch: f32, aspect: f32) -> Camera {
        let (lo, hi) = (Vec3::from(lo), Vec3::from(hi));
        let centre = 0.5 * (lo + hi);
        let dir = Vec3::new(pitch.cos() * yaw.cos(), pitch.cos() * yaw.sin(), pitch.sin());
        let right = Vec3::Z.cross(dir).try_normalize().unwrap_or(Vec3::X);
        let up = dir.cross(right);
        let (mut half_w, mut half_h, mut half_d) = (0f32, 0f32, 0f32);
        for k in 0..8 {
            let corner = Vec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            ) - centre;
            half_w = half_w.max(corner.dot(right).abs());
            half_h = half_h.max(corner.dot(up).abs());
            half_d = half_d.max(corner.dot(dir).abs());
        }
        let radius = (half_w / aspect.max(0.2)).max(half_h).max(1e-6) / 0.6;
        let fov_y = 35f32.to_radians();
        Camera {
            target: (0.5 * (lo + hi)).into(),
            // the near side of the box is half its depth closer than the target
            distance: radius / (0.5 * fov_y).tan() + half_d,
            yaw,
            pitch,
            fov_y,
        }
    }

    pub fn eye(&self) -> Vec3 {
        let dir = Vec3::new(self.pitch.cos() * self.yaw.cos(), self.pitch.cos() * self.yaw.sin(), self.pitch.sin());
        Vec3::from(self.target) + self.distance * dir
    }

    pub fn view(&self) -> Mat4 {
        Mat4::look_at_rh(self.eye(), Vec3::from(self.target), Vec3::Z)
    }

    pub fn view_projection(&self, aspect: f32) -> Mat4 {
        let near = (0.01 * self.distance).max(1e-4);
        Mat4::perspective_rh_gl(self.fov_y, aspect.max(1e-3), near, 100.0 * self.distance + 10.0) * self.view()
    }

    /// Orbit by a mouse drag of `(dx, dy)` points.
    pub fn orbit(&mut self, dx: f32, dy: f32) {
        self.yaw -= 0.008 * dx;
        self.pitch = (self.pitch + 0.008 * dy).clamp(-1.55, 1.55);
    }

    /// Pan by a drag of `(dx, dy)` points in a view `height_px` tall.
    pub fn pan(&mut self, dx: f32, dy: f32, height_px: f32) {
        let view = self.view();
        let right = Vec3::new(view.x_axis.x, view.y_axis.x, view.z_axis.x);
        let up = Vec3::new(view.x_axis.y, view.y_axis.y, view.z_axis.y);
        let metres_per_px = 2.0 * self.distance * (0.5 * self.fov_y).tan() / height_px.max(1.0);
        self.target = (Vec3::from(self.target) - right * dx * metres_per_px + up * dy * metres_per_px).into();
    }

    /// Zoom by `factor` (> 1 moves closer).
    pub fn zoom(&mut self, factor: f32) {
        self.distance = (self.distance / factor.max(1e-3)).clamp(1e-3, 1e4);
    }
}

/// A triangle mesh to draw: per-vertex positions, normals and colours.
#[derive(Clone, Debug, Default)]
pub struct TriangleLayer {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub colours: Vec<[u8; 3]>,
    pub triangles: Vec<[u32; 3]>,
}

/// Line segments and points to draw over the triangles (depth-tested, not depth-writing).
#[derive(Clone, Debug, Default)]
pub struct Overlay {
    pub lines: Vec<([f32; 3], [f32; 3], [u8; 4])>,
    /// Centre, half size in pixels, colour.
    pub points: Vec<([f32; 3], f32, [u8; 4])>,
}

/// The rendered picture: RGBA pixels and NDC depth, row by row from the top.
pub struct Image {
    pub width: usize,
    pub height: usize,
    pub rgba: Vec<[u8; 4]>,
    pub depth: Vec<f32>,
    view_projection: Mat4,
}

/// A triangle in screen space, ready to rasterise.
struct ScreenTriangle {
    p: [[f32; 3]; 3],
    c: [[f32; 3]; 3],
    min_y: i32,
    max_y: i32,
}

pub const BACKGROUND: [u8; 4] = [24, 26, 32, 255];

impl Image {
    pub fn new(width: usize, height: usize) -> Image {
        Image {
            width,
            height,
            rgba: vec![BACKGROUND; width * height],
            depth: vec![f32::INFINITY; width * height],
            view_projection: Mat4::IDENTITY,
        }
    }

    /// Projects a world point to pixel coordinates and NDC depth (None behind the camera).
    pub fn project(&self, p: [f32; 3]) -> Option<[f32; 3]> {
        project(&self.view_projection, self.width, self.height, p)
    }

    /// The world point at pixel `(x, y)` and NDC depth `z` (the inverse of [`Image::project`]).
    pub fn unproject(&self, x: f32, y: f32, z: f32) -> Option<[f32; 3]> {
        let ndc = Vec4::new(2.0 * x / self.width as f32 - 1.0, 1.0 - 2.0 * y / self.height as f32, z, 1.0);
        let p = self.view_projection.inverse() * ndc;
        (p.w.abs() > 1e-12).then(|| (p.truncate() / p.w).into())
    }

    /// Whether a projected point is not hidden by the drawn surfaces.
    pub fn visible(&self, p: [f32; 3]) -> bool {
        let (x, y) = (p[0] as i64, p[1] as i64);
        if x < 0 || y < 0 || x >= self.width as i64 || y >= self.height as i64 {
            return false;
        }
        p[2] <= self.depth[y as usize * self.width + x as usize] + 2e-3
    }

    /// Takes `camera` for [`Image::project`] and [`Image::unproject`] without drawing.
    pub fn set_camera(&mut self, camera: &Camera) {
        self.view_projection = camera.view_projection(self.width as f32 / self.height.max(1) as f32);
    }

    /// The view-projection matrix of the last camera, column-major.
    pub fn view_projection(&self) -> [f32; 16] {
        self.view_projection.to_cols_array()
    }

    /// Clears and draws `layers` then `overlay` seen by `camera`.
    pub fn render(&mut self, camera: &Camera, layers: &[&TriangleLayer], overlay: &Overlay) {
        let (w, h) = (self.width, self.height);
        self.set_camera(camera);
        let vp = self.view_projection;
        let eye = camera.eye();
        let mut tris = Vec::new();
        for layer in layers {
            let screen: Vec<Option<[f32; 3]>> = layer.positions.iter().map(|&p| project(&vp, w, h, p)).collect();
            let shade: Vec<[f32; 3]> = layer
                .positions
                .iter()
                .zip(&layer.normals)
                .zip(&layer.colours)
                .map(|((&p, &n), &c)| shade(p, n, c, eye))
                .collect();
            for t in &layer.triangles {
                let [a, b, c] = t.map(|i| i as usize);
                let (Some(pa), Some(pb), Some(pc)) = (screen[a], screen[b], screen[c]) else { continue };
                let min_y = pa[1].min(pb[1]).min(pc[1]).floor().max(0.0) as i32;
                let max_y = pa[1].max(pb[1]).max(pc[1]).ceil().min(h as f32 - 1.0) as i32;
                if max_y < min_y {
                    continue;
                }
                tris.push(ScreenTriangle { p: [pa, pb, pc], c: [shade[a], shade[b], shade[c]], min_y, max_y });
            }
        }
        let band_rows = h.div_ceil(4 * rayon::current_num_threads().max(1)).max(8);
        self.rgba.par_chunks_mut(band_rows * w).zip(self.depth.par_chunks_mut(band_rows * w)).enumerate().for_each(
            |(band, (rgba, depth))| {
                rgba.fill(BACKGROUND);
                depth.fill(f32::INFINITY);
                let y0 = (band * band_rows) as i32;
                let y1 = y0 + (rgba.len() / w) as i32 - 1;
                for t in tris.iter().filter(|t| t.max_y >= y0 && t.min_y <= y1) {
                    raster_triangle(t, w, y0, y1, rgba, depth);
                }
            },
        );
        for &(a, b, colour) in &overlay.lines {
            if let (Some(pa), Some(pb)) = (project(&vp, w, h, a), project(&vp, w, h, b)) {
                self.line(pa, pb, colour);
            }
        }
        for &(p, half, colour) in &overlay.points {
            if let Some(s) = project(&vp, w, h, p) {
                self.point(s, half, colour);
            }
        }
    }

    /// Depth-tested pixel write with a small bias, so lines on a surface stay visible.
    fn plot(&mut self, x: i32, y: i32, z: f32, colour: [u8; 4]) {
        if x < 0 || y < 0 || x >= self.width as i32 || y >= self.height as i32 {
            return;
        }
        let i = y as usize * self.width + x as usize;
        if z <= self.depth[i] + 2e-4 {
            let a = colour[3] as u32;
            let dst = &mut self.rgba[i];
            for k in 0..3 {
                dst[k] = ((colour[k] as u32 * a + dst[k] as u32 * (255 - a)) / 255) as u8;
            }
        }
    }

    fn line(&mut self, a: [f32; 3], b: [f32; 3], colour: [u8; 4]) {
        let steps = (b[0] - a[0]).abs().max((b[1] - a[1]).abs()).ceil().clamp(1.0, 8192.0) as i32;
        for s in 0..=steps {
            let f = s as f32 / steps as f32;
            let x = a[0] + f * (b[0] - a[0]);
            let y = a[1] + f * (b[1] - a[1]);
            let z = a[2] + f * (b[2] - a[2]);
            self.plot(x.round() as i32, y.round() as i32, z, colour);
        }
    }

    fn point(&mut self, p: [f32; 3], half: f32, colour: [u8; 4]) {
        let r = half.ceil() as i32;
        let (cx, cy) = (p[0].round() as i32, p[1].round() as i32);
        for dy in -r..=r {
            for dx in -r..=r {
                if ((dx * dx + dy * dy) as f32) <= half * half + 0.5 {
                    self.plot(cx + dx, cy + dy, p[2] - 1e-3, colour);
                }
            }
        }
    }
}

/// Lambert shading with a head light, both sides lit: the colour of a surface vertex at `p`
/// with normal `n` and base colour `c` seen from `eye`, 0…255 per channel.
pub fn shade(p: [f32; 3], n: [f32; 3], c: [u8; 3], eye: Vec3) -> [f32; 3] {
    let to_eye = (eye - Vec3::from(p)).normalize_or_zero();
    let lambert = Vec3::from(n).dot(to_eye).abs();
    let k = 0.35 + 0.65 * lambert;
    [c[0] as f32 * k, c[1] as f32 * k, c[2] as f32 * k]
}

fn project(vp: &Mat4, w: usize, h: usize, p: [f32; 3]) -> Option<[f32; 3]> {
    let c: Vec4 = *vp * Vec4::new(p[0], p[1], p[2], 1.0);
    if c.w <= 1e-6 {
        return None;
    }
    let ndc = c.truncate() / c.w;
    if !(ndc.z > -1.0 && ndc.z < 1.0 && ndc.x.is_finite() && ndc.y.is_finite()) {
        return None;
    }
    Some([(0.5 * (ndc.x + 1.0)) * w as f32, (0.5 * (1.0 - ndc.y)) * h as f32, ndc.z])
}

/// Rasterises `t` into the band of rows `y0..=y1` (`rgba`, `depth` hold just those rows).
fn raster_triangle(t: &ScreenTriangle, w: usize, y0: i32, y1: i32, rgba: &mut [[u8; 4]], depth: &mut [f32]) {
    let [a, b, c] = t.p;
    let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    if area.abs() < 1e-12 {
        return;
    }
    let inv_area = 1.0 / area;
    let min_x = a[0].min(b[0]).min(c[0]).floor().max(0.0) as i32;
    let max_x = a[0].max(b[0]).max(c[0]).ceil().min(w as f32 - 1.0) as i32;
    for y in t.min_y.max(y0)..=t.max_y.min(y1) {
        let py = y as f32 + 0.5;
        let row = (y - y0) as usize * w;
        for x in min_x..=max_x {
            let px = x as f32 + 0.5;
            // barycentric weights by edge functions (either winding: both sides drawn)
            let w0 = ((b[0] - px) * (c[1] - py) - (b[1] - py) * (c[0] - px)) * inv_area;
            let w1 = ((c[0] - px) * (a[1] - py) - (c[1] - py) * (a[0] - px)) * inv_area;
            let w2 = 1.0 - w0 - w1;
            if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                continue;
            }
            let z = w0 * a[2] + w1 * b[2] + w2 * c[2];
            let i = row + x as usize;
            if z < depth[i] {
                depth[i] = z;
                let colour: [u8; 3] =
                    std::array::from_fn(|k| (w0 * t.c[0][k] + w1 * t.c[1][k] + w2 * t.c[2][k]).clamp(0.0, 255.0) as u8);
                rgba[i] = [colour[0], colour[1], colour[2], 255];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(z: f32, colour: [u8; 3]) -> TriangleLayer {
        TriangleLayer {
            positions: vec![[-1.0, -1.0, z], [1.0, -1.0, z], [1.0, 1.0, z], [-1.0, 1.0, z]],
            normals: vec![[0.0, 0.0, 1.0]; 4],
            colours: vec![colour; 4],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        }
    }

    fn top_view() -> Camera {
        Camera { target: [0.0, 0.0, 0.0], distance: 10.0, yaw: 0.0, pitch: 1.5, fov_y: 0.5 }
    }

    #[test]
    fn nearer_surface_hides_farther_whatever_the_order() {
        let (near, far) = (square(1.0, [255, 0, 0]), square(-1.0, [0, 0, 255]));
        for layers in [[&near, &far], [&far, &near]] {
            let mut img = Image::new(64, 48);
            img.render(&top_view(), &layers, &Overlay::default());
            let centre = img.rgba[24 * 64 + 32];
            assert!(centre[0] > 100 && centre[2] == 0, "{centre:?}");
        }
    }

    #[test]
    fn background_outside_and_lines_hidden_behind_surfaces() {
        let near = square(1.0, [200, 200, 200]);
        let overlay = Overlay {
            lines: vec![
                ([-3.0, 0.0, -2.0], [3.0, 0.0, -2.0], [255, 0, 0, 255]),
                ([-3.0, 0.5, 2.0], [3.0, 0.5, 2.0], [0, 255, 0, 255]),
            ],
            points: vec![],
        };
        let mut img = Image::new(80, 60);
        img.render(&top_view(), &[&near], &overlay);
        assert_eq!(img.rgba[0], BACKGROUND);
        let reds = img.rgba.iter().filter(|c| c[0] == 255 && c[1] == 0).count();
        let greens = img.rgba.iter().filter(|c| c[1] == 255 && c[0] == 0).count();
        assert!(greens > 20, "the line in front is drawn ({greens} px)");
        // the line below the square shows only outside the square's silhouette
        let s = img.project([1.0, 0.0, 1.0]).unwrap();
        let inside_red = (0..80)
            .filter(|&x| (x as f32) < s[0] - 1.0 && img.rgba[30 * 80 + x][0] == 255 && img.rgba[30 * 80 + x][1] == 0)
            .count();
        assert!(reds > 0 && inside_red < reds, "{reds} {inside_red}");
    }

    #[test]
    fn project_maps_the_target_to_the_centre() {
        let mut img = Image::new(100, 50);
        let cam = Camera::framing([0.0, 0.0, 0.0], [2.0, 0.5, 0.5]);
        img.render(&cam, &[], &Overlay::default());
        let c = img.project(cam.target).unwrap();
        assert!((c[0] - 50.0).abs() < 1e-3 && (c[1] - 25.0).abs() < 1e-3, "{c:?}");
    }
}
