//! [`ApngEncoder`], an animated PNG written frame by frame (so a long animation never sits in
//! memory whole), playing at a fixed frame rate and looping.

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
}
