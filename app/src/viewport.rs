//! The photo view: zoom (wheel, pinch, ctrl+wheel) from 1/64 to 16 screen points per photo
//! pixel about the cursor, fit, pan by dragging with the middle or right button (or the left
//! with space held), and a loupe for sub-pixel placing.
//!
//! Photos are decoded on the studio's worker ([`PhotoLoader`], [`crate::worker::Worker`]) into 8-bit tiles of at most
//! [`TILE_PX`] and one downsampled mip level whose long side is at most [`MIP_MAX_PX`]. The mip
//! is uploaded first and drawn whenever it is sharp enough or a tile is not uploaded yet; full
//! resolution tiles are uploaded lazily, only when visible and only [`UPLOADS_PER_FRAME`] per
//! frame, so opening a 24 MP photo never stalls a frame on a texture upload (the tiled pyramid
//! of image viewers such as OpenSeadragon, reduced to two levels).
//!
//! Coordinates: photo pixels use the library's pixel-centre convention (`camera` module: (0, 0)
//! is the centre of the top-left pixel), so the image spans −½ … W−½. [`ViewTransform`] maps
//! photo pixels to screen points and back in f64.
//!
//! # Known limitations
//! Two levels only (full and one mip); a photo between the mip and full resolution at a zoom
//! just under 1 shows the full tiles minified by the GPU's linear filter (no trilinear
//! filtering). Decoded tiles of every opened photo stay in memory until the site is closed.

use eframe::egui::{self, Color32, ColorImage, Pos2, Rect, TextureHandle, TextureOptions, Vec2};
use photomontage::colour::tonemap::{ToneMap, encode_srgb8};
use photomontage::photo::{self, Transfer};
use std::path::PathBuf;

use crate::worker::{Poll, Worker};

/// Largest tile side in pixels.
pub const TILE_PX: u32 = 1024;
/// Longest side of the mip level.
pub const MIP_MAX_PX: u32 = 2048;
/// Full-resolution tiles uploaded per frame at most.
pub const UPLOADS_PER_FRAME: usize = 2;
/// Zoom limits (screen points per photo pixel).
pub const ZOOM_MIN: f64 = 1.0 / 64.0;
/// See [`ZOOM_MIN`].
pub const ZOOM_MAX: f64 = 16.0;

/// The mapping between photo pixels and screen points of one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewTransform {
    /// The screen rectangle of the view.
    pub rect: Rect,
    /// Screen points per photo pixel.
    pub zoom: f64,
    /// Photo pixel shown at the centre of `rect`.
    pub centre_px: [f64; 2],
}

impl ViewTransform {
    /// Screen position of a photo pixel position.
    #[must_use]
    pub fn screen_from_photo(&self, p_px: [f64; 2]) -> Pos2 {
        let c = self.rect.center();
        Pos2::new(
            (f64::from(c.x) + (p_px[0] - self.centre_px[0]) * self.zoom) as f32,
            (f64::from(c.y) + (p_px[1] - self.centre_px[1]) * self.zoom) as f32,
        )
    }

    /// Photo pixel position under a screen position.
    #[must_use]
    pub fn photo_from_screen(&self, p: Pos2) -> [f64; 2] {
        let c = self.rect.center();
        [
            self.centre_px[0] + (f64::from(p.x) - f64::from(c.x)) / self.zoom,
            self.centre_px[1] + (f64::from(p.y) - f64::from(c.y)) / self.zoom,
        ]
    }

    /// Screen rectangle of a photo pixel rectangle given by its pixel-edge corners.
    #[must_use]
    pub fn screen_rect(&self, min_px: [f64; 2], max_px: [f64; 2]) -> Rect {
        Rect::from_min_max(
            self.screen_from_photo(min_px),
            self.screen_from_photo(max_px),
        )
    }
}

/// Zoom and pan of the photo view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Viewport {
    /// Screen points per photo pixel.
    pub zoom: f64,
    /// Photo pixel at the centre of the view.
    pub centre_px: [f64; 2],
    /// Follows the view size (fit) until the user zooms or pans.
    pub fitted: bool,
}

impl Default for Viewport {
    fn default() -> Self {
        Self {
            zoom: 1.0,
            centre_px: [0.0, 0.0],
            fitted: true,
        }
    }
}

impl Viewport {
    /// Fits a photo of `size_px` into `rect`.
    pub fn fit(&mut self, rect: Rect, size_px: [u32; 2]) {
        let (w, h) = (f64::from(size_px[0].max(1)), f64::from(size_px[1].max(1)));
        self.zoom = (f64::from(rect.width()) / w)
            .min(f64::from(rect.height()) / h)
            .clamp(ZOOM_MIN, ZOOM_MAX);
        self.centre_px = [w / 2.0 - 0.5, h / 2.0 - 0.5];
        self.fitted = true;
    }

    /// Multiplies the zoom by `factor` keeping the photo point under `anchor` fixed.
    pub fn zoom_about(&mut self, rect: Rect, anchor: Pos2, factor: f64) {
        let t = self.transform(rect);
        let p = t.photo_from_screen(anchor);
        let zoom = (self.zoom * factor).clamp(ZOOM_MIN, ZOOM_MAX);
        let c = rect.center();
        self.centre_px = [
            p[0] - (f64::from(anchor.x) - f64::from(c.x)) / zoom,
            p[1] - (f64::from(anchor.y) - f64::from(c.y)) / zoom,
        ];
        self.zoom = zoom;
        self.fitted = false;
    }

    /// Moves the view by a screen delta (the photo follows the pointer).
    pub fn pan(&mut self, delta: Vec2) {
        self.centre_px[0] -= f64::from(delta.x) / self.zoom;
        self.centre_px[1] -= f64::from(delta.y) / self.zoom;
        self.fitted = false;
    }

    /// The transform of this view in `rect`.
    #[must_use]
    pub fn transform(&self, rect: Rect) -> ViewTransform {
        ViewTransform {
            rect,
            zoom: self.zoom,
            centre_px: self.centre_px,
        }
    }
}

/// One full-resolution tile: pixel origin and size, the pixels until uploaded, the texture after.
pub struct Tile {
    pub origin_px: [u32; 2],
    pub size_px: [u32; 2],
    image: Option<ColorImage>,
    texture: Option<TextureHandle>,
}

/// A decoded photo ready for display (all 8-bit sRGB).
pub struct DecodedPhoto {
    pub size_px: [u32; 2],
    pub tiles: Vec<Tile>,
    /// Integer downsampling factor of the mip level.
    pub mip_factor: u32,
    mip_image: Option<ColorImage>,
    mip_texture: Option<TextureHandle>,
}

/// An sRGB-encoded value in 0–1 to its 8-bit code.
fn quantise(v: f32) -> u8 {
    // Clamped to 0–255 first, so the cast cannot wrap.
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// Converts one decoded photo to display tiles and a mip level (runs on the worker).
#[must_use]
pub fn prepare_display(image: &photo::PhotoImage) -> DecodedPhoto {
    let [w, h] = image.size_px();
    let tone = ToneMap::clamp();
    let px = image.pixels.as_raw();
    // 8-bit sRGB of the whole photo, row-major RGBA.
    let srgb: Vec<[u8; 3]> = match image.transfer {
        Transfer::Srgb => px
            .chunks_exact(3)
            .map(|c| [quantise(c[0]), quantise(c[1]), quantise(c[2])])
            .collect(),
        Transfer::Linear => px
            .chunks_exact(3)
            .map(|c| encode_srgb8([c[0], c[1], c[2]], &tone))
            .collect(),
    };
    let at = |x: u32, y: u32| srgb[(y as usize) * (w as usize) + x as usize];
    let mut tiles = Vec::new();
    let mut ty = 0;
    while ty < h {
        let th = TILE_PX.min(h - ty);
        let mut tx = 0;
        while tx < w {
            let tw = TILE_PX.min(w - tx);
            let mut rgba = Vec::with_capacity((tw * th * 4) as usize);
            for y in ty..ty + th {
                for x in tx..tx + tw {
                    let [r, g, b] = at(x, y);
                    rgba.extend_from_slice(&[r, g, b, 255]);
                }
            }
            tiles.push(Tile {
                origin_px: [tx, ty],
                size_px: [tw, th],
                image: Some(ColorImage::from_rgba_unmultiplied(
                    [tw as usize, th as usize],
                    &rgba,
                )),
                texture: None,
            });
            tx += tw;
        }
        ty += th;
    }
    // Box-filtered mip level (averaged in the 8-bit encoding: a preview, not photometry).
    let mip_factor = w.max(h).div_ceil(MIP_MAX_PX).max(1);
    let (mw, mh) = (w.div_ceil(mip_factor), h.div_ceil(mip_factor));
    let mut mip = Vec::with_capacity((mw * mh * 4) as usize);
    for my in 0..mh {
        for mx in 0..mw {
            let mut sum = [0u32; 3];
            let mut n = 0;
            for y in my * mip_factor..((my + 1) * mip_factor).min(h) {
                for x in mx * mip_factor..((mx + 1) * mip_factor).min(w) {
                    let p = at(x, y);
                    sum[0] += u32::from(p[0]);
                    sum[1] += u32::from(p[1]);
                    sum[2] += u32::from(p[2]);
                    n += 1;
                }
            }
            let n = n.max(1);
            mip.extend_from_slice(&[
                (sum[0] / n) as u8,
                (sum[1] / n) as u8,
                (sum[2] / n) as u8,
                255,
            ]);
        }
    }
    DecodedPhoto {
        size_px: [w, h],
        tiles,
        mip_factor,
        mip_image: Some(ColorImage::from_rgba_unmultiplied(
            [mw as usize, mh as usize],
            &mip,
        )),
        mip_texture: None,
    }
}

const TEXTURE_OPTIONS: TextureOptions = TextureOptions {
    magnification: egui::TextureFilter::Nearest,
    minification: egui::TextureFilter::Linear,
    wrap_mode: egui::TextureWrapMode::ClampToEdge,
    mipmap_mode: None,
};

impl DecodedPhoto {
    /// Whether every full-resolution tile is on the GPU.
    #[must_use]
    pub fn all_tiles_uploaded(&self) -> bool {
        self.tiles.iter().all(|t| t.texture.is_some())
    }

    /// Draws the photo with `t` into `painter` (clipped to its clip rect), uploading the mip and
    /// up to [`UPLOADS_PER_FRAME`] visible tiles. Returns whether uploads remain (repaint).
    pub fn paint(
        &mut self,
        ctx: &egui::Context,
        painter: &egui::Painter,
        t: &ViewTransform,
    ) -> bool {
        let clip = painter.clip_rect();
        if let Some(img) = self.mip_image.take() {
            self.mip_texture = Some(ctx.load_texture("photo-mip", img, TEXTURE_OPTIONS));
        }
        let [w, h] = self.size_px;
        let full = t.screen_rect([-0.5, -0.5], [f64::from(w) - 0.5, f64::from(h) - 0.5]);
        // The mip is enough while one mip pixel covers at most one screen point.
        let mip_sharp = t.zoom * f64::from(self.mip_factor) <= 1.0;
        // Visible tiles, uploading up to UPLOADS_PER_FRAME of those still on the CPU.
        let mut visible = Vec::new();
        let mut uploads = 0;
        let mut pending = false;
        if !mip_sharp {
            for (i, tile) in self.tiles.iter_mut().enumerate() {
                let [x0, y0] = tile.origin_px.map(f64::from);
                let [tw, th] = tile.size_px.map(f64::from);
                let r = t.screen_rect([x0 - 0.5, y0 - 0.5], [x0 + tw - 0.5, y0 + th - 0.5]);
                if !r.intersects(clip) {
                    continue;
                }
                if tile.texture.is_none()
                    && uploads < UPLOADS_PER_FRAME
                    && let Some(img) = tile.image.take()
                {
                    tile.texture =
                        Some(ctx.load_texture(format!("photo-tile-{i}"), img, TEXTURE_OPTIONS));
                    uploads += 1;
                }
                match &tile.texture {
                    Some(tex) => visible.push((tex.id(), r)),
                    None => pending = true,
                }
            }
        }
        // The mip is drawn when it is sharp enough, or under tiles not uploaded yet (drawing it
        // under a complete set of tiles would only cost fill rate).
        if mip_sharp || pending {
            if let Some(mip) = &self.mip_texture {
                let mip_w = f64::from(w.div_ceil(self.mip_factor) * self.mip_factor);
                let mip_h = f64::from(h.div_ceil(self.mip_factor) * self.mip_factor);
                let r = t.screen_rect([-0.5, -0.5], [mip_w - 0.5, mip_h - 0.5]);
                painter.image(
                    mip.id(),
                    r,
                    Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0)),
                    Color32::WHITE,
                );
            } else {
                painter.rect_filled(full, 0.0, Color32::from_gray(40));
            }
        }
        for (id, r) in visible {
            painter.image(
                id,
                r,
                Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0)),
                Color32::WHITE,
            );
        }
        pending
    }
}

/// A photo decode finished on the worker.
pub struct Decoded {
    pub photo_id: String,
    pub result: Result<DecodedPhoto, String>,
}

/// Decodes photos on the studio's [`Worker`], one worker (thread) per requested photo.
#[derive(Default)]
pub struct PhotoLoader {
    in_flight: Vec<(String, Worker<Result<DecodedPhoto, String>>)>,
}

impl PhotoLoader {
    /// Starts decoding `path` for `photo_id`; `ctx` is woken when it is done.
    pub fn request(&mut self, photo_id: String, path: PathBuf, ctx: &egui::Context) {
        let mut worker = Worker::new(format!("decode {photo_id}"));
        let spawned = worker.spawn(ctx, move |_| {
            photo::load(&path)
                .map(|img| prepare_display(&img))
                .map_err(|e| e.to_string())
        });
        if spawned {
            self.in_flight.push((photo_id, worker));
        }
    }

    /// Decodes that finished since the last call (a panicking decoder is a failed decode).
    pub fn poll(&mut self) -> Vec<Decoded> {
        let mut done = Vec::new();
        self.in_flight.retain_mut(|(photo_id, worker)| {
            let result = match worker.poll() {
                Poll::Running(_) => return true,
                Poll::Done(r) => r,
                Poll::Failed(e) => Err(e),
                Poll::Cancelled | Poll::Idle => Err(format!("decoding {photo_id} stopped")),
            };
            done.push(Decoded {
                photo_id: std::mem::take(photo_id),
                result,
            });
            false
        });
        done
    }

    /// Whether a decode is running.
    #[must_use]
    pub fn busy(&self) -> bool {
        !self.in_flight.is_empty()
    }
}

/// Draws a loupe: `t`'s photo around `at_px` magnified into `loupe_rect`, with a crosshair.
pub fn paint_loupe(
    ctx: &egui::Context,
    painter: &egui::Painter,
    photo: &mut DecodedPhoto,
    loupe_rect: Rect,
    at_px: [f64; 2],
    zoom: f64,
) {
    let p = painter.with_clip_rect(loupe_rect);
    p.rect_filled(loupe_rect, 0.0, Color32::BLACK);
    let t = ViewTransform {
        rect: loupe_rect,
        zoom,
        centre_px: at_px,
    };
    let _ = photo.paint(ctx, &p, &t);
    let c = loupe_rect.center();
    let stroke = egui::Stroke::new(1.0, Color32::from_rgb(255, 60, 60));
    p.line_segment(
        [Pos2::new(loupe_rect.left(), c.y), Pos2::new(c.x - 4.0, c.y)],
        stroke,
    );
    p.line_segment(
        [
            Pos2::new(c.x + 4.0, c.y),
            Pos2::new(loupe_rect.right(), c.y),
        ],
        stroke,
    );
    p.line_segment(
        [Pos2::new(c.x, loupe_rect.top()), Pos2::new(c.x, c.y - 4.0)],
        stroke,
    );
    p.line_segment(
        [
            Pos2::new(c.x, c.y + 4.0),
            Pos2::new(c.x, loupe_rect.bottom()),
        ],
        stroke,
    );
    painter.rect_stroke(
        loupe_rect,
        0.0,
        egui::Stroke::new(1.0, Color32::WHITE),
        egui::StrokeKind::Outside,
    );
}

/// The parts of `outer` not covered by `inner`: up to four bands (top, bottom, left, right).
#[must_use]
pub fn outside(outer: Rect, inner: Rect) -> Vec<Rect> {
    let inner = inner.intersect(outer);
    if !inner.is_positive() {
        return vec![outer];
    }
    let bands = [
        Rect::from_min_max(outer.min, Pos2::new(outer.max.x, inner.min.y)),
        Rect::from_min_max(Pos2::new(outer.min.x, inner.max.y), outer.max),
        Rect::from_min_max(
            Pos2::new(outer.min.x, inner.min.y),
            Pos2::new(inner.min.x, inner.max.y),
        ),
        Rect::from_min_max(
            Pos2::new(inner.max.x, inner.min.y),
            Pos2::new(outer.max.x, inner.max.y),
        ),
    ];
    bands.into_iter().filter(|r| r.is_positive()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// f32 screen coordinates carry ~1e-7 relative error; at 1000 points that is 1e-4 points,
    /// i.e. 1e-4/zoom photo px.
    const ROUND_TRIP_TOL_PX: f64 = 1e-3;

    #[test]
    fn transform_round_trips_and_zoom_keeps_the_anchor() {
        let rect = Rect::from_min_size(Pos2::new(10.0, 20.0), Vec2::new(800.0, 600.0));
        let mut v = Viewport::default();
        v.fit(rect, [1600, 1200]);
        assert!((v.zoom - 0.5).abs() < 1e-12, "800/1600 and 600/1200");
        let t = v.transform(rect);
        // The image's outer edges land on the view's edges.
        let tl = t.screen_from_photo([-0.5, -0.5]);
        assert!((tl.x - 10.0).abs() < 1e-3 && (tl.y - 20.0).abs() < 1e-3);
        let p = [123.25, 456.75];
        let back = t.photo_from_screen(t.screen_from_photo(p));
        assert!((back[0] - p[0]).abs() < ROUND_TRIP_TOL_PX);
        assert!((back[1] - p[1]).abs() < ROUND_TRIP_TOL_PX);
        let anchor = Pos2::new(300.0, 250.0);
        let under = t.photo_from_screen(anchor);
        v.zoom_about(rect, anchor, 7.0);
        let after = v.transform(rect).photo_from_screen(anchor);
        assert!((after[0] - under[0]).abs() < ROUND_TRIP_TOL_PX);
        assert!((after[1] - under[1]).abs() < ROUND_TRIP_TOL_PX);
        v.zoom_about(rect, anchor, 1e9);
        assert!((v.zoom - ZOOM_MAX).abs() < 1e-12, "clamped at 16:1");
        v.zoom_about(rect, anchor, 1e-12);
        assert!((v.zoom - ZOOM_MIN).abs() < 1e-12, "clamped at 1:64");
    }

    #[test]
    fn tiles_cover_the_photo_and_the_mip_averages() {
        let (w, h) = (2500u32, 1100u32);
        let mut pixels = image::Rgb32FImage::new(w, h);
        for (x, _, p) in pixels.enumerate_pixels_mut() {
            let v = if x % 2 == 0 { 1.0 } else { 0.0 };
            *p = image::Rgb([v, v, v]);
        }
        let d = prepare_display(&photo::PhotoImage {
            pixels,
            transfer: Transfer::Srgb,
        });
        let area: u64 = d
            .tiles
            .iter()
            .map(|t| u64::from(t.size_px[0]) * u64::from(t.size_px[1]))
            .sum();
        assert_eq!(area, u64::from(w) * u64::from(h));
        assert!(
            d.tiles
                .iter()
                .all(|t| t.size_px[0] <= TILE_PX && t.size_px[1] <= TILE_PX)
        );
        assert_eq!(d.mip_factor, 2, "2500 px → 1250 ≤ 2048");
        let mip = d.mip_image.as_ref().expect("mip");
        assert_eq!(mip.size, [1250, 550]);
        // Alternate columns 255/0 average to 127 (integer division of 510/4).
        assert_eq!(mip.pixels[0].r(), 127);
    }

    #[test]
    fn outside_bands_cover_exactly_the_outer_area_minus_the_inner() {
        let outer = Rect::from_min_max(Pos2::new(0.0, 0.0), Pos2::new(100.0, 50.0));
        let inner = Rect::from_min_max(Pos2::new(10.0, 5.0), Pos2::new(60.0, 45.0));
        let bands = outside(outer, inner);
        assert_eq!(bands.len(), 4);
        // Areas are sums of small integers: exact in f32.
        let area: f32 = bands.iter().map(|r| r.area()).sum();
        assert_eq!(area.to_bits(), (5000.0f32 - 2000.0).to_bits());
        for (a, b) in bands.iter().zip(bands.iter().skip(1)) {
            assert!(!a.intersect(*b).is_positive());
        }
        assert!(bands.iter().all(|r| !r.intersect(inner).is_positive()));
        // A photo covering the view leaves nothing; one outside it leaves the whole view.
        let cover = Rect::from_min_max(Pos2::new(-5.0, -5.0), Pos2::new(200.0, 90.0));
        assert!(outside(outer, cover).is_empty());
        let away = Rect::from_min_max(Pos2::new(300.0, 0.0), Pos2::new(400.0, 50.0));
        assert_eq!(outside(outer, away), vec![outer]);
    }
}
