//! OpenEXR's PIZ decompression of one block of up to 32 scanlines, as the OpenEXR library
//! defines it: a table of the 16-bit words the block holds, a Huffman code (with runs) over
//! their indices, and a Haar wavelet per channel, undone in that order.

use crate::error::ImageError;
use crate::io::decode_err;

/// Scanlines in one PIZ block.
pub(crate) const PIZ_LINES: usize = 32;

/// Bytes of the bitmap of words present: one bit for each 16-bit word.
const BITMAP_SIZE: usize = (1 << 16) / 8;
/// Huffman symbols: every 16-bit word, and one more.
const SYMBOLS: usize = (1 << 16) + 1;
/// The longest Huffman code.
const LONGEST: usize = 58;

/// The scanline bytes (channel after channel within each line, little-endian) of a PIZ
/// block of `lines` lines of `width` samples, whose channels take `words[c]` 16-bit words a
/// sample (1 for half, 2 for float and uint), in the file's channel order.
pub(crate) fn unpiz(
    block: &[u8],
    words: &[usize],
    (width, lines): (usize, usize),
    what: &str,
) -> Result<Vec<u8>, ImageError> {
    let bad = |m: &str| decode_err(what, format!("a PIZ block {m}"));
    let total: usize = words.iter().map(|w| w * width * lines).sum();
    let take = |at: usize, n: usize| block.get(at..at + n).ok_or_else(|| bad("is cut short"));
    let u16_at = |at: usize| take(at, 2).map(|b| usize::from(u16::from_le_bytes([b[0], b[1]])));
    // The words present, as a bitmap over the bytes `min..=max`.
    let (min, max) = (u16_at(0)?, u16_at(2)?);
    if max >= BITMAP_SIZE {
        return Err(bad("has a bitmap past its end"));
    }
    let mut bitmap = vec![0u8; BITMAP_SIZE];
    let mut at = 4;
    if min <= max {
        bitmap[min..=max].copy_from_slice(take(at, max - min + 1)?);
        at += max - min + 1;
    }
    let (table, most) = words_present(&bitmap);
    let length = take(at, 4).map(|b| i32::from_le_bytes([b[0], b[1], b[2], b[3]]))?;
    let length = usize::try_from(length).map_err(|_| bad("has a negative length"))?;
    let coded = take(at + 4, length)?;
    let mut buf = vec![0u16; total];
    huffman_decode(coded, &mut buf).map_err(bad)?;
    let mut start = 0;
    for &w in words {
        let n = w * width * lines;
        for j in 0..w {
            wavelet_decode(
                &mut buf[start..start + n],
                j,
                (width, w),
                (lines, width * w),
                most,
            );
        }
        start += n;
    }
    for v in &mut buf {
        *v = table[usize::from(*v)];
    }
    // From one plane per channel to lines of channels.
    let mut out = Vec::with_capacity(2 * total);
    for y in 0..lines {
        let mut plane = 0;
        for &w in words {
            let row = &buf[plane + y * width * w..plane + (y + 1) * width * w];
            out.extend(row.iter().flat_map(|v| v.to_le_bytes()));
            plane += w * width * lines;
        }
    }
    Ok(out)
}

/// The words the bitmap marks (0 always), in order, then zeros: index `k` of the block's
/// data stands for `table[k]`; and the largest index in use.
fn words_present(bitmap: &[u8]) -> (Vec<u16>, u16) {
    let mut table = vec![0u16; 1 << 16];
    let mut k = 0;
    for i in 0..1usize << 16 {
        if i == 0 || bitmap[i >> 3] & (1 << (i & 7)) != 0 {
            table[k] = i as u16;
            k += 1;
        }
    }
    (table, (k - 1) as u16)
}

/// Bits read from the most significant end of each byte on.
struct Bits<'a> {
    data: &'a [u8],
    at: usize,
}

impl Bits<'_> {
    /// The next `n` bits (at most 32) as a number.
    fn read(&mut self, n: usize) -> Result<u64, &'static str> {
        if self.at + n > 8 * self.data.len() {
            return Err("is cut short");
        }
        let mut v = 0u64;
        for _ in 0..n {
            let bit = self.data[self.at >> 3] >> (7 - (self.at & 7)) & 1;
            v = v << 1 | u64::from(bit);
            self.at += 1;
        }
        Ok(v)
    }
}

/// Decodes OpenEXR's Huffman stream `data` into exactly `out.len()` words: a header (the
/// first and last symbols with a code, and the number of bits of code), the code lengths
/// (6 bits each, runs of zeros shortened), then the codes, the last symbol meaning "repeat
/// the previous word as often as the next 8 bits say".
fn huffman_decode(data: &[u8], out: &mut [u16]) -> Result<(), &'static str> {
    if data.is_empty() {
        return if out.is_empty() {
            Ok(())
        } else {
            Err("holds too few words")
        };
    }
    let word = |at: usize| -> Result<usize, &'static str> {
        let b = data.get(at..at + 4).ok_or("is cut short")?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
    };
    let (first, last, n_bits) = (word(0)?, word(4)?, word(12)?);
    if first >= SYMBOLS || last >= SYMBOLS {
        return Err("has a Huffman table out of range");
    }
    let mut bits = Bits {
        data: &data[20.min(data.len())..],
        at: 0,
    };
    let mut lengths = vec![0u8; SYMBOLS];
    let mut i = first;
    while i <= last {
        let l = bits.read(6)? as usize;
        let zeros = match l {
            63 => bits.read(8)? as usize + 6,
            59..=62 => l - 59 + 2,
            _ => {
                lengths[i] = l as u8;
                i += 1;
                continue;
            }
        };
        if i + zeros > last + 1 {
            return Err("has a Huffman table too long");
        }
        i += zeros;
    }
    // The canonical code: the codes of each length are consecutive from `start[l]`, in the
    // order of their symbols; longer codes take the smaller numbers.
    let mut count = [0u64; LONGEST + 1];
    for &l in &lengths {
        count[usize::from(l)] += 1;
    }
    let mut start = [0u64; LONGEST + 1];
    let mut c = 0u64;
    for l in (1..=LONGEST).rev() {
        start[l] = c;
        c = (c + count[l]) >> 1;
    }
    let mut offset = [0usize; LONGEST + 2];
    for l in 1..=LONGEST {
        offset[l + 1] = offset[l] + count[l] as usize;
    }
    let mut symbols = vec![0u32; offset[LONGEST + 1]];
    let mut next = offset;
    for (s, &l) in lengths.iter().enumerate() {
        if l > 0 {
            symbols[next[usize::from(l)]] = s as u32;
            next[usize::from(l)] += 1;
        }
    }
    // The codes start at the byte after the table.
    let coded = &bits.data[bits.at.div_ceil(8)..];
    if n_bits > 8 * coded.len() {
        return Err("has fewer bits than it says");
    }
    let mut bits = Bits { data: coded, at: 0 };
    let (mut code, mut l, mut n) = (0u64, 0usize, 0usize);
    while bits.at < n_bits {
        code = code << 1 | bits.read(1)?;
        l += 1;
        if l > LONGEST {
            return Err("has a code no symbol has");
        }
        if code < start[l] || code - start[l] >= count[l] {
            continue;
        }
        let symbol = symbols[offset[l] + (code - start[l]) as usize] as usize;
        (code, l) = (0, 0);
        if symbol == last {
            if bits.at + 8 > n_bits {
                return Err("is cut short");
            }
            let run = bits.read(8)? as usize;
            if n == 0 || n + run > out.len() {
                return Err("repeats past its words");
            }
            let previous = out[n - 1];
            out[n..n + run].fill(previous);
            n += run;
        } else {
            *out.get_mut(n).ok_or("holds too many words")? = symbol as u16;
            n += 1;
        }
    }
    if n != out.len() {
        return Err("holds too few words");
    }
    Ok(())
}

/// Undoes the 2D Haar wavelet on the words `buf[base + y oy + x ox]`, `x < nx`, `y < ny`,
/// in 14-bit arithmetic when every word is below `1 << 14` (`most`), else modulo `1 << 16`.
fn wavelet_decode(
    buf: &mut [u16],
    base: usize,
    (nx, ox): (usize, usize),
    (ny, oy): (usize, usize),
    most: u16,
) {
    let narrow = most < 1 << 14;
    let dec = |l: u16, h: u16| if narrow { wdec14(l, h) } else { wdec16(l, h) };
    let n = nx.min(ny);
    let mut p = 1usize;
    while p <= n {
        p <<= 1;
    }
    p >>= 1;
    let mut p2 = p;
    p >>= 1;
    while p >= 1 {
        let (oy1, oy2, ox1, ox2) = (oy * p, oy * p2, ox * p, ox * p2);
        let mut py = base;
        let ey = base + oy * (ny - p2);
        while py <= ey {
            let mut px = py;
            let ex = py + ox * (nx - p2);
            while px <= ex {
                let (p01, p10) = (px + ox1, px + oy1);
                let p11 = p10 + ox1;
                let (i00, i10) = dec(buf[px], buf[p10]);
                let (i01, i11) = dec(buf[p01], buf[p11]);
                (buf[px], buf[p01]) = dec(i00, i01);
                (buf[p10], buf[p11]) = dec(i10, i11);
                px += ox2;
            }
            // An odd column.
            if nx & p != 0 {
                let p10 = px + oy1;
                (buf[px], buf[p10]) = dec(buf[px], buf[p10]);
            }
            py += oy2;
        }
        // An odd line.
        if ny & p != 0 {
            let mut px = py;
            let ex = py + ox * (nx - p2);
            while px <= ex {
                let p01 = px + ox1;
                (buf[px], buf[p01]) = dec(buf[px], buf[p01]);
                px += ox2;
            }
        }
        p2 = p;
        p >>= 1;
    }
}

/// One step of the 14-bit wavelet back: the pair whose mean and difference are `l`, `h`.
fn wdec14(l: u16, h: u16) -> (u16, u16) {
    let (ls, hi) = (i32::from(l as i16), i32::from(h as i16));
    let ai = ls + (hi & 1) + (hi >> 1);
    (ai as i16 as u16, (ai - hi) as i16 as u16)
}

/// One step of the 16-bit (modular) wavelet back.
fn wdec16(l: u16, h: u16) -> (u16, u16) {
    let (m, d) = (i32::from(l), i32::from(h));
    let b = (m - (d >> 1)) & 0xffff;
    let a = (d + b - (1 << 15)) & 0xffff;
    (a as u16, b as u16)
}
