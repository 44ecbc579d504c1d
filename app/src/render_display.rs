//! The Render panel's display images: the photo and the render tone-mapped to sRGB and
//! subsampled (nearest pixel) to at most [`MAX_DISPLAY_SIDE_PX`] on the long side, and the
//! progressive [`Preview`] into which each finished tile's pixels are written and uploaded with
//! a partial texture update.
//!
//! # Known limitations
//! Nearest-pixel subsampling (no filtering) for display; export is at full resolution.

use eframe::egui::{self, Color32};
use photomontage::colour::ToneMap;
use photomontage::colour::tonemap::encode_srgb8;
use photomontage::render::{RenderedImage, TileProgress};
use rayon::prelude::*;

/// Longest side of the preview texture; larger montages are subsampled for display only.
pub const MAX_DISPLAY_SIDE_PX: u32 = 2048;

/// The progressive preview of a running render: the photo's display image with each finished
/// tile's pixels written in, uploaded to the GPU by partial texture updates.
pub struct Preview {
    /// The photo rendered.
    pub photo_id: String,
    /// Full-resolution size of the render.
    pub size_px: [u32; 2],
    step: u32,
    image: egui::ColorImage,
    texture: Option<egui::TextureHandle>,
    /// Regions changed since the last upload: (display-pixel origin, pixels).
    dirty: Vec<([usize; 2], egui::ColorImage)>,
}

impl Preview {
    /// A preview of `photo_id` (full size `size_px`) starting from `base`, the photo's display
    /// image made with [`display_rgb`].
    #[must_use]
    pub fn new(photo_id: &str, size_px: [u32; 2], base: egui::ColorImage) -> Self {
        Self {
            photo_id: photo_id.to_owned(),
            size_px,
            step: display_step(size_px),
            image: base,
            texture: None,
            dirty: Vec::new(),
        }
    }

    /// The preview's pixels now (display resolution).
    #[must_use]
    pub fn image(&self) -> &egui::ColorImage {
        &self.image
    }

    /// Writes a finished tile's pixels (tone-mapped with `tone_map`) into the preview and
    /// queues the changed region for upload.
    pub fn apply_tile(&mut self, tile: &TileProgress, tone_map: &ToneMap) {
        let step = self.step;
        let [x0, y0] = tile.origin_px;
        let [tw, th] = tile.size_px;
        if tile.rgb_linear.len() != (tw * th) as usize
            || x0 + tw > self.size_px[0]
            || y0 + th > self.size_px[1]
        {
            return;
        }
        // Display pixels whose sample (d·step) falls inside the tile.
        let (dx0, dx1) = (x0.div_ceil(step), (x0 + tw).div_ceil(step));
        let (dy0, dy1) = (y0.div_ceil(step), (y0 + th).div_ceil(step));
        if dx0 >= dx1 || dy0 >= dy1 {
            return;
        }
        let (dw, dh) = ((dx1 - dx0) as usize, (dy1 - dy0) as usize);
        let mut pixels = Vec::with_capacity(dw * dh);
        let width = self.image.size[0];
        for dy in dy0..dy1 {
            for dx in dx0..dx1 {
                let (x, y) = (dx * step - x0, dy * step - y0);
                let [r, g, b] = encode_srgb8(tile.rgb_linear[(y * tw + x) as usize], tone_map);
                let c = Color32::from_rgb(r, g, b);
                if let Some(p) = self.image.pixels.get_mut(dy as usize * width + dx as usize) {
                    *p = c;
                }
                pixels.push(c);
            }
        }
        self.dirty.push((
            [dx0 as usize, dy0 as usize],
            egui::ColorImage::new([dw, dh], pixels),
        ));
    }

    /// Uploads the changed regions (the whole image the first time) and returns the texture.
    pub(crate) fn texture(&mut self, ctx: &egui::Context) -> &egui::TextureHandle {
        let dirty = std::mem::take(&mut self.dirty);
        if let Some(t) = &mut self.texture {
            for (pos, img) in dirty {
                t.set_partial(pos, img, egui::TextureOptions::LINEAR);
            }
        }
        self.texture.get_or_insert_with(|| {
            ctx.load_texture(
                format!("preview {}", self.photo_id),
                self.image.clone(),
                egui::TextureOptions::LINEAR,
            )
        })
    }
}

/// Subsampling step of the display image of a `size_px` render (1 up to
/// [`MAX_DISPLAY_SIDE_PX`]).
#[must_use]
pub fn display_step(size_px: [u32; 2]) -> u32 {
    size_px[0]
        .max(size_px[1])
        .div_ceil(MAX_DISPLAY_SIDE_PX)
        .max(1)
}

/// The display image (nearest-pixel subsampled by [`display_step`], sRGB through `tone_map`)
/// of linear RGB pixels `rgb_at(x, y)` of a `size_px` image.
#[must_use]
pub fn display_rgb(
    size_px: [u32; 2],
    rgb_at: impl Fn(u32, u32) -> [f32; 3] + Sync,
    tone_map: &ToneMap,
) -> egui::ColorImage {
    let [w, h] = size_px;
    let step = display_step(size_px);
    let (dw, dh) = (w.div_ceil(step), h.div_ceil(step));
    let mut pixels = vec![Color32::BLACK; (dw * dh) as usize];
    // Rows in parallel (each pixel on its own: the same image on any number of threads).
    pixels
        .par_chunks_mut(dw.max(1) as usize)
        .zip(0..dh)
        .for_each(|(row, y)| {
            for (p, x) in row.iter_mut().zip(0..dw) {
                let [r, g, b] = encode_srgb8(rgb_at(x * step, y * step), tone_map);
                *p = Color32::from_rgb(r, g, b);
            }
        });
    egui::ColorImage::new([dw as usize, dh as usize], pixels)
}

/// The display image of a finished render.
#[must_use]
pub fn display_image(image: &RenderedImage, tone_map: &ToneMap) -> egui::ColorImage {
    let w = image.size_px[0];
    display_rgb(
        image.size_px,
        |x, y| {
            let p = image.rgba[(y * w + x) as usize];
            [p[0], p[1], p[2]]
        },
        tone_map,
    )
}

/// The display image of the (linear) photo a render starts from.
#[must_use]
pub fn display_photo(photo_linear: &image::Rgb32FImage, tone_map: &ToneMap) -> egui::ColorImage {
    display_rgb(
        [photo_linear.width(), photo_linear.height()],
        |x, y| photo_linear.get_pixel(x, y).0,
        tone_map,
    )
}
