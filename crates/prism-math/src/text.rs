//! [`LineIndex`]: the line number of a byte offset in a text, in constant time per query,
//! for readers that name lines in their errors.

/// Bytes between checkpoints: a query scans at most this many bytes.
const STRIDE: usize = 4096;

/// Line numbers of byte offsets in a text. Built in one pass; each query counts newlines
/// from the nearest checkpoint at or before the offset, so it costs at most 4096 bytes
/// whatever the offset (a scan from the start would make reading a large file quadratic).
#[derive(Clone, Debug)]
pub struct LineIndex<'t> {
    text: &'t [u8],
    /// Newlines before each multiple of the stride.
    newlines_before: Vec<u32>,
}

impl<'t> LineIndex<'t> {
    /// Indexes `text`.
    #[must_use]
    pub fn new(text: &'t str) -> Self {
        let text = text.as_bytes();
        let mut newlines_before = Vec::with_capacity(text.len() / STRIDE + 1);
        let mut count = 0u32;
        for chunk in text.chunks(STRIDE) {
            newlines_before.push(count);
            let n = chunk.iter().filter(|&&b| b == b'\n').count();
            count = count.saturating_add(u32::try_from(n).unwrap_or(u32::MAX));
        }
        newlines_before.push(count);
        LineIndex {
            text,
            newlines_before,
        }
    }

    /// The 1-based line holding byte `offset` (offsets past the end count as the end).
    #[must_use]
    pub fn line(&self, offset: usize) -> u32 {
        let offset = offset.min(self.text.len());
        let k = offset / STRIDE;
        let tail = &self.text[k * STRIDE..offset];
        let n = tail.iter().filter(|&&b| b == b'\n').count() as u32;
        1 + self.newlines_before[k] + n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force: every offset of a text with lines of varied lengths (some longer than
    /// the stride) gets the line a scan from the start gives.
    #[test]
    fn lines_match_a_scan_from_the_start() {
        let mut text = String::new();
        for i in 0..300 {
            text.push_str(&"x".repeat((i * 97) % 9000));
            text.push('\n');
        }
        let index = LineIndex::new(&text);
        let mut line = 1;
        for (offset, b) in text.bytes().enumerate() {
            assert_eq!(index.line(offset), line, "offset {offset}");
            if b == b'\n' {
                line += 1;
            }
        }
        assert_eq!(index.line(text.len()), line);
        assert_eq!(index.line(usize::MAX), line);
        assert_eq!(LineIndex::new("").line(0), 1);
    }
}
