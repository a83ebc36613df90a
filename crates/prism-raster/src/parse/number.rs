//! The SVG number lexer both dialects and path data share: the longest number prefix of a
//! string, and its value read at the dialect's precision.

/// How numbers are rounded on reading: the course renderer reads `f32`.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Precision {
    /// Read as `f32`, then widened: the course's dialect.
    F32,
    /// Read as `f64`: standard SVG and path data.
    F64,
}

/// Length of the longest prefix of `s` that is an SVG number (sign, digits, fraction,
/// exponent), or 0.
pub(crate) fn number_prefix_len(s: &str) -> usize {
    let b = s.as_bytes();
    let mut i = 0;
    if i < b.len() && (b[i] == b'+' || b[i] == b'-') {
        i += 1;
    }
    let digits_start = i;
    while i < b.len() && b[i].is_ascii_digit() {
        i += 1;
    }
    let mut any = i > digits_start;
    if i < b.len() && b[i] == b'.' {
        let j = i + 1;
        let mut k = j;
        while k < b.len() && b[k].is_ascii_digit() {
            k += 1;
        }
        if k > j || any {
            any = any || k > j;
            i = k;
        }
    }
    if !any {
        return 0;
    }
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        let mut k = i + 1;
        if k < b.len() && (b[k] == b'+' || b[k] == b'-') {
            k += 1;
        }
        let ds = k;
        while k < b.len() && b[k].is_ascii_digit() {
            k += 1;
        }
        if k > ds {
            i = k;
        }
    }
    i
}

/// The number in `s`, rounded as `p` says; `None` unless it is finite.
pub(crate) fn to_num(s: &str, p: Precision) -> Option<f64> {
    let v = match p {
        Precision::F32 => s.parse::<f32>().ok().map(f64::from),
        Precision::F64 => s.parse::<f64>().ok(),
    }?;
    v.is_finite().then_some(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn number_prefixes() {
        assert_eq!(number_prefix_len("487.211px"), 7);
        assert_eq!(number_prefix_len(".5.5"), 2);
        assert_eq!(number_prefix_len("-1e-3x"), 5);
        assert_eq!(number_prefix_len("1em"), 1);
        assert_eq!(number_prefix_len("abc"), 0);
        assert_eq!(number_prefix_len("-."), 0);
    }
}
