//! An 8-bit RGB raster, row-major from the top-left, and its PNG encoding.
//!
//! The pictures need a pixel buffer and a PNG writer, nothing else: the buffer is this struct and
//! the encoder is the `png` crate (the encoder the `image` crate itself calls). `image` was used
//! before and pulled colour management (`moxcms`, `pxfm`) that no picture here uses: about 90 s of
//! CPU in a first build on 2 cores.

/// An RGB image, 8 bits per channel, row-major from the top-left corner.
///
/// ```
/// use sim::picture::Raster;
/// let mut img = Raster::from_pixel(4, 3, [10, 20, 30]);
/// img.put_pixel(1, 2, [255, 0, 0]);
/// assert_eq!(img.get_pixel(1, 2), [255, 0, 0]);
/// assert_eq!(img.get_pixel(0, 0), [10, 20, 30]);
/// assert_eq!((img.width(), img.height()), (4, 3));
/// let png = img.to_png().unwrap();
/// assert_eq!(&png[1..4], b"PNG");
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Raster {
    width: u32,
    height: u32,
    /// `3 * width * height` bytes: R, G, B per pixel.
    rgb: Vec<u8>,
}

impl Raster {
    /// A black raster of `width` x `height` pixels.
    pub fn new(width: u32, height: u32) -> Self {
        Self::from_pixel(width, height, [0, 0, 0])
    }

    /// A raster of `width` x `height` pixels, all of colour `rgb`.
    pub fn from_pixel(width: u32, height: u32, rgb: [u8; 3]) -> Self {
        let n = width as usize * height as usize;
        Self { width, height, rgb: rgb.repeat(n) }
    }

    /// Wraps `rgb` (R, G, B per pixel, row-major); `None` unless it holds exactly
    /// `3 * width * height` bytes.
    pub fn from_raw(width: u32, height: u32, rgb: Vec<u8>) -> Option<Self> {
        (rgb.len() == 3 * width as usize * height as usize).then_some(Self { width, height, rgb })
    }

    /// Width, pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height, pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The bytes, R, G, B per pixel, row-major from the top-left.
    pub fn as_raw(&self) -> &[u8] {
        &self.rgb
    }

    fn offset(&self, x: u32, y: u32) -> usize {
        assert!(x < self.width && y < self.height, "pixel ({x}, {y}) outside {}x{}", self.width, self.height);
        3 * (y as usize * self.width as usize + x as usize)
    }

    /// Sets pixel `(x, y)`. Panics outside the raster (callers clip; an outside pixel is a bug).
    pub fn put_pixel(&mut self, x: u32, y: u32, rgb: [u8; 3]) {
        let o = self.offset(x, y);
        self.rgb[o..o + 3].copy_from_slice(&rgb);
    }

    /// Pixel `(x, y)`. Panics outside the raster.
    pub fn get_pixel(&self, x: u32, y: u32) -> [u8; 3] {
        let o = self.offset(x, y);
        [self.rgb[o], self.rgb[o + 1], self.rgb[o + 2]]
    }

    /// Every pixel, row-major from the top-left.
    pub fn pixels(&self) -> impl Iterator<Item = [u8; 3]> + '_ {
        self.rgb.chunks_exact(3).map(|p| [p[0], p[1], p[2]])
    }

    /// Copies `top` onto this raster with its top-left corner at `(x, y)`, clipped to this raster.
    pub fn paste(&mut self, top: &Raster, x: u32, y: u32) {
        let w = top.width.min(self.width.saturating_sub(x)) as usize;
        for row in 0..top.height.min(self.height.saturating_sub(y)) {
            let src = 3 * row as usize * top.width as usize;
            let dst = self.offset(x, y + row);
            self.rgb[dst..dst + 3 * w].copy_from_slice(&top.rgb[src..src + 3 * w]);
        }
    }

    /// The raster encoded as an 8-bit RGB PNG.
    pub fn to_png(&self) -> Result<Vec<u8>, png::EncodingError> {
        let mut bytes = Vec::new();
        let mut encoder = png::Encoder::new(&mut bytes, self.width, self.height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_compression(png::Compression::Balanced);
        let mut writer = encoder.write_header()?;
        writer.write_image_data(&self.rgb)?;
        writer.finish()?;
        Ok(bytes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paste_clips_to_the_raster() {
        let mut base = Raster::new(4, 4);
        let top = Raster::from_pixel(3, 3, [9, 9, 9]);
        base.paste(&top, 2, 2);
        assert_eq!(base.pixels().filter(|p| *p == [9, 9, 9]).count(), 4);
        assert_eq!(base.get_pixel(3, 3), [9, 9, 9]);
        assert_eq!(base.get_pixel(1, 1), [0, 0, 0]);
        assert!(Raster::from_raw(2, 2, vec![0; 11]).is_none());
    }

    #[test]
    fn png_decodes_to_the_same_pixels() {
        let mut img = Raster::new(5, 2);
        img.put_pixel(4, 1, [1, 2, 3]);
        let png = img.to_png().unwrap();
        let decoder = png::Decoder::new(std::io::Cursor::new(png));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height, info.color_type), (5, 2, png::ColorType::Rgb));
        assert_eq!(&buf[..info.buffer_size()], img.as_raw());
    }
}
