//! [`ApngEncoder`] and [`GifEncoder`]: animations written frame by frame (so a long
//! animation never sits in memory whole), playing at a fixed frame rate and looping.

use std::io::Write;

use crate::error::ImageError;
use crate::Rgb8Image;

/// An animated PNG of a known number of frames of one size, written as they come.
pub struct ApngEncoder<W: Write> {
    writer: png::Writer<W>,
    size: (u32, u32),
    left: u32,
}

fn err(e: png::EncodingError) -> ImageError {
    ImageError::Encode {
        format: "PNG",
        message: e.to_string(),
    }
}

impl<W: Write> ApngEncoder<W> {
    /// Starts an animation of `frames` frames of `width x height` at `fps` frames a
    /// second, looping forever.
    ///
    /// # Errors
    /// [`ImageError::Encode`] for a zero size or frame count, or the encoder's error.
    pub fn new(
        out: W,
        width: u32,
        height: u32,
        frames: u32,
        fps: u16,
    ) -> Result<ApngEncoder<W>, ImageError> {
        if width == 0 || height == 0 || frames == 0 || fps == 0 {
            return Err(ImageError::Encode {
                format: "PNG",
                message: format!("an animation needs a size, frames and a rate, found {width} x {height}, {frames} frames, {fps} fps"),
            });
        }
        let mut enc = png::Encoder::new(out, width, height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::Fast);
        enc.set_animated(frames, 0).map_err(err)?;
        enc.set_frame_delay(1, fps).map_err(err)?;
        Ok(ApngEncoder {
            writer: enc.write_header().map_err(err)?,
            size: (width, height),
            left: frames,
        })
    }

    /// Adds the next frame.
    ///
    /// # Errors
    /// [`ImageError::Encode`] for a frame of another size, one too many, or the encoder's
    /// error.
    pub fn push(&mut self, frame: &Rgb8Image) -> Result<(), ImageError> {
        if (frame.width(), frame.height()) != self.size || self.left == 0 {
            return Err(ImageError::Encode {
                format: "PNG",
                message: format!(
                    "an animation frame must be {} x {} and within the count",
                    self.size.0, self.size.1
                ),
            });
        }
        self.writer
            .write_image_data(frame.pixels().as_flattened())
            .map_err(err)?;
        self.left -= 1;
        Ok(())
    }

    /// Ends the animation.
    ///
    /// # Errors
    /// [`ImageError::Encode`] if frames are missing, or the encoder's error.
    pub fn finish(self) -> Result<(), ImageError> {
        if self.left != 0 {
            return Err(ImageError::Encode {
                format: "PNG",
                message: format!("{} animation frames missing", self.left),
            });
        }
        self.writer.finish().map_err(err)
    }
}

/// An animated GIF, written frame by frame: each frame quantised to its own palette of 256
/// colours (NeuQuant), looping. GIF counts time in hundredths of a second and viewers slow
/// down frames shorter than 2, so the frame time is `100 / fps` hundredths rounded, at least
/// 2 (90 frames a second play at 50).
pub struct GifEncoder<W: Write> {
    writer: gif::Encoder<W>,
    size: (u16, u16),
    delay: u16,
}

fn gif_err(e: impl std::fmt::Display) -> ImageError {
    ImageError::Encode {
        format: "GIF",
        message: e.to_string(),
    }
}

impl<W: Write> GifEncoder<W> {
    /// Starts a looping animation of `width x height` at `fps` frames a second.
    ///
    /// # Errors
    /// [`ImageError::Encode`] for a zero or over 65535 size, a zero rate, or the encoder's
    /// error.
    pub fn new(out: W, width: u32, height: u32, fps: u16) -> Result<GifEncoder<W>, ImageError> {
        let size = (u16::try_from(width), u16::try_from(height));
        let (Ok(w), Ok(h)) = size else {
            return Err(gif_err(format!(
                "a GIF is at most 65535 pixels a side, found {width} x {height}"
            )));
        };
        if w == 0 || h == 0 || fps == 0 {
            return Err(gif_err(format!(
                "an animation needs a size and a rate, found {width} x {height}, {fps} fps"
            )));
        }
        let mut writer = gif::Encoder::new(out, w, h, &[]).map_err(gif_err)?;
        writer.set_repeat(gif::Repeat::Infinite).map_err(gif_err)?;
        let delay = ((100.0 / f64::from(fps)).round() as u16).max(2);
        Ok(GifEncoder {
            writer,
            size: (w, h),
            delay,
        })
    }

    /// Adds the next frame.
    ///
    /// # Errors
    /// [`ImageError::Encode`] for a frame of another size, or the encoder's error.
    pub fn push(&mut self, frame: &Rgb8Image) -> Result<(), ImageError> {
        let (w, h) = self.size;
        if (frame.width(), frame.height()) != (u32::from(w), u32::from(h)) {
            return Err(gif_err(format!("an animation frame must be {w} x {h}")));
        }
        let mut f = gif::Frame::from_rgb_speed(w, h, frame.pixels().as_flattened(), 10);
        f.delay = self.delay;
        self.writer.write_frame(&f).map_err(gif_err)
    }

    /// Ends the animation.
    ///
    /// # Errors
    /// The encoder's error.
    pub fn finish(self) -> Result<(), ImageError> {
        self.writer.into_inner().map(drop).map_err(gif_err)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Round trip: the png crate reads back an animation of three frames, each as written.
    #[test]
    fn frames_read_back() {
        let frames: Vec<Rgb8Image> = (0..3u8)
            .map(|i| crate::Image::from_fn(4, 3, |x, y| [i * 40, x as u8 * 10, y as u8 * 20]))
            .collect();
        let mut bytes = Vec::new();
        let mut enc = ApngEncoder::new(&mut bytes, 4, 3, 3, 30).unwrap();
        for f in &frames {
            enc.push(f).unwrap();
        }
        enc.finish().unwrap();
        let dec = png::Decoder::new(std::io::Cursor::new(&bytes));
        let mut reader = dec.read_info().unwrap();
        assert_eq!(reader.info().animation_control().unwrap().num_frames, 3);
        let mut buf = vec![0; reader.output_buffer_size()];
        for f in &frames {
            reader.next_frame(&mut buf).unwrap();
            assert_eq!(&buf[..36], f.pixels().as_flattened());
        }
        let mut short = ApngEncoder::new(Vec::new(), 4, 3, 2, 30).unwrap();
        short.push(&frames[0]).unwrap();
        assert!(short.finish().is_err());
    }

    /// Round trip: the gif crate reads back three frames of few colours exactly (a
    /// 256-colour palette holds them), with the frame time and loop.
    #[test]
    fn gif_frames_read_back() {
        let frames: Vec<Rgb8Image> = (0..3u8)
            .map(|i| crate::Image::from_fn(6, 5, |x, _| [i * 100, if x < 3 { 0 } else { 255 }, 50]))
            .collect();
        let mut bytes = Vec::new();
        let mut enc = GifEncoder::new(&mut bytes, 6, 5, 90).unwrap();
        for f in &frames {
            enc.push(f).unwrap();
        }
        enc.finish().unwrap();
        let mut opts = gif::DecodeOptions::new();
        opts.set_color_output(gif::ColorOutput::RGBA);
        let mut dec = opts.read_info(std::io::Cursor::new(&bytes)).unwrap();
        for f in &frames {
            let got = dec.read_next_frame().unwrap().unwrap();
            assert_eq!(got.delay, 2);
            let rgb: Vec<u8> = got
                .buffer
                .chunks(4)
                .flat_map(|p| [p[0], p[1], p[2]])
                .collect();
            assert_eq!(rgb, f.pixels().as_flattened());
        }
        assert!(dec.read_next_frame().unwrap().is_none());
        assert!(GifEncoder::new(Vec::new(), 70000, 5, 30).is_err());
    }
}
