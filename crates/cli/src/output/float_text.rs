//! [`push_f32`]: an f32 as the shortest decimal that reads back to it, laid out exactly
//! as Rust's `{:?}` writes it (the CLI's CSV contract), several times faster: the
//! digits come from `ryu` (the same shortest digits: both implement the shortest
//! round-trip), the layout is `{:?}`'s: plain decimal with at least one fractional digit
//! for `1e-4 <= |v| < 1e16` and zero, otherwise `d.ddde<exp>` (`1e-5`, `1.5e20`);
//! `NaN`, `inf`, `-inf` as `{:?}`. A tie (a value exactly halfway between two shortest
//! forms) is rounded up in magnitude, as `{:?}` does (ryu rounds to even). The test
//! compares the two on 20 million bit patterns and 2.9 million short binary fractions.

/// Appends `v` to `out` as `format!("{v:?}")` would.
pub fn push_f32(out: &mut String, v: f32, ryu: &mut ryu::Buffer) {
    // the common case: ryu writes `{:?}`'s text itself. ryu's layout is plain for a
    // shortest decimal in [1e-6, 1e13) (`pretty::format32`), `{:?}`'s for a value in
    // [1e-4, 1e16): both plain in [1e-4, 1e12) (the upper bound kept a decade below
    // ryu's so that a value whose shortest decimal rounds up to 1e13 stays out), with the
    // same digits unless the value can tie
    if (1e-4..1e12).contains(&v.abs()) && !may_tie(v) {
        out.push_str(ryu.format_finite(v));
        return;
    }
    if !v.is_finite() {
        use std::fmt::Write as _;
        let _ = write!(out, "{v:?}");
        return;
    }
    let text = ryu.format_finite(v);
    let (negative, text) = match text.strip_prefix('-') {
        Some(rest) => (true, rest),
        None => (false, text),
    };
    let significant = Significant::of(text);
    let mut point = significant.point;
    // a tie: `v` exactly halfway between two shortest candidates; ryu takes the even
    // one, `{:?}` the one of larger magnitude
    let mut rounded = [0u8; 48];
    let digits = match tie_rounded_up(v, significant.digits(), &mut rounded) {
        Some((len, carried)) => {
            point += i32::from(carried);
            rounded.get(..len).unwrap_or(&[])
        }
        None => significant.digits(),
    };
    let mut text = Text { buf: [0; 48], len: 0 };
    if negative {
        text.push(b"-");
    }
    if digits.is_empty() {
        text.push(b"0.0");
    } else if (1e-4..1e16).contains(&v.abs()) {
        text.plain(digits, point);
    } else {
        text.scientific(digits, point);
    }
    out.push_str(std::str::from_utf8(text.buf.get(..text.len).unwrap_or(&[])).unwrap_or(""));
}

/// The significant digits of ryu's text of a finite, non-negative f32 and where the
/// decimal point is: value = `0.DIGITS x 10^point`.
struct Significant {
    buf: [u8; 48],
    start: usize,
    end: usize,
    point: i32,
}

impl Significant {
    fn of(text: &str) -> Self {
        let (mantissa, exp) = match text.bytes().position(|b| b == b'e' || b == b'E') {
            Some(i) => (text.get(..i).unwrap_or(""), text.get(i + 1..).and_then(|e| e.parse::<i32>().ok()).unwrap_or(0)),
            None => (text, 0),
        };
        let (int, frac) = match mantissa.bytes().position(|b| b == b'.') {
            Some(i) => (mantissa.get(..i).unwrap_or(""), mantissa.get(i + 1..).unwrap_or("")),
            None => (mantissa, ""),
        };
        // ryu writes at most 9 significant digits and 7 leading zeros for an f32 ("0.0000001")
        let mut buf = [0u8; 48];
        let mut n = 0;
        for b in int.bytes().chain(frac.bytes()) {
            if let Some(slot) = buf.get_mut(n) {
                *slot = b;
                n += 1;
            }
        }
        let all = buf.get(..n).unwrap_or(&[]);
        let lead = all.iter().take_while(|&&d| d == b'0').count();
        let trail = all.iter().rev().take_while(|&&d| d == b'0').count();
        Self { buf, start: lead, end: n.saturating_sub(trail).max(lead), point: int.len() as i32 + exp - lead as i32 }
    }

    fn digits(&self) -> &[u8] {
        self.buf.get(self.start..self.end).unwrap_or(&[])
    }
}

/// A float's text, assembled in place (ASCII only).
struct Text {
    buf: [u8; 48],
    len: usize,
}

impl Text {
    fn push(&mut self, bytes: &[u8]) {
        for &b in bytes {
            if let Some(slot) = self.buf.get_mut(self.len) {
                *slot = b;
                self.len += 1;
            }
        }
    }

    fn zeros(&mut self, n: usize) {
        for _ in 0..n {
            self.push(b"0");
        }
    }

    /// `0.000DIGITS`, `DIGITS000.0` or `DIG.ITS` (value `0.DIGITS x 10^point`).
    fn plain(&mut self, digits: &[u8], point: i32) {
        let n = digits.len() as i32;
        if point <= 0 {
            self.push(b"0.");
            self.zeros((-point) as usize);
            self.push(digits);
        } else if point >= n {
            self.push(digits);
            self.zeros((point - n) as usize);
            self.push(b".0");
        } else {
            let (a, b) = digits.split_at(point as usize);
            self.push(a);
            self.push(b".");
            self.push(b);
        }
    }

    /// `D.IGITSe<exp>` (value `0.DIGITS x 10^point`, `exp = point - 1`).
    fn scientific(&mut self, digits: &[u8], point: i32) {
        let (first, rest) = digits.split_at(1);
        self.push(first);
        if !rest.is_empty() {
            self.push(b".");
            self.push(rest);
        }
        self.push(b"e");
        let mut itoa = [0u8; 12];
        let e = point - 1;
        let mut k = itoa.len();
        let mut x = e.unsigned_abs();
        loop {
            k -= 1;
            if let Some(slot) = itoa.get_mut(k) {
                *slot = b'0' + (x % 10) as u8;
            }
            x /= 10;
            if x == 0 {
                break;
            }
        }
        if e < 0 {
            self.push(b"-");
        }
        self.push(itoa.get(k..).unwrap_or(&[]));
    }
}

/// Whether `|v| = m 2^e` (`m` odd) has an exact decimal expansion short enough to tie
/// (`-14 <= e <= 33`, see [`tie_rounded_up`]); false for most values, cheaply.
fn may_tie(v: f32) -> bool {
    let bits = v.abs().to_bits();
    let (biased, frac) = ((bits >> 23) as i32, bits & 0x7f_ffff);
    let (m, e) = if biased == 0 { (frac, -149) } else { (frac | 0x80_0000, biased - 150) };
    m != 0 && (-14..=33).contains(&(e + m.trailing_zeros() as i32))
}

/// When `|v|` lies exactly halfway between `digits` and `digits + 1` (in the last
/// place) and ryu took `digits`: the digits rounded up in magnitude into `out`, their
/// count and whether the carry added a digit in front (`999` -> `1000`). The exact
/// decimal expansion of `|v| = m 2^e` (`m` odd) is `m 5^-e` times a power of ten
/// (`e < 0`) or the integer `m 2^e`: a tie needs at most 10 significant digits, so only
/// `-14 <= e <= 33` can tie (computed exactly in `u64`).
fn tie_rounded_up(v: f32, digits: &[u8], out: &mut [u8; 48]) -> Option<(usize, bool)> {
    const POW5: [u64; 15] = {
        let mut p = [1u64; 15];
        let mut i = 1;
        while i < 15 {
            p[i] = p[i - 1] * 5;
            i += 1;
        }
        p
    };
    let bits = v.abs().to_bits();
    let (biased, frac) = ((bits >> 23) as i32, bits & 0x7f_ffff);
    let (m, e) = if biased == 0 { (frac, -149) } else { (frac | 0x80_0000, biased - 150) };
    if m == 0 {
        return None;
    }
    let (m, e) = (m >> m.trailing_zeros(), e + m.trailing_zeros() as i32);
    // the exact value's significant digits: below 10^10 for a tie (n <= 9 digits), so
    // 5^-e < 10^10 (e >= -14) or 2^e < 10^10 (e <= 33)
    let exact: u64 = if e < 0 {
        u64::from(m) * *POW5.get((-e) as usize)?
    } else if e <= 33 {
        u64::from(m) << e
    } else {
        return None;
    };
    // a tie has n + 1 significant digits (the exact value's last one a 5, after no
    // trailing zero: m is odd, so m 5^k and m 2^e end in no 0): below 10^(n+1)
    if exact >= 10u64.pow(digits.len() as u32 + 1) {
        return None;
    }
    let mut text = [0u8; 40];
    let mut len = 0;
    let mut x = exact;
    while x > 0 {
        if let Some(slot) = text.get_mut(len) {
            *slot = b'0' + (x % 10) as u8;
        }
        x /= 10;
        len += 1;
    }
    let exact_digits = text.get_mut(..len)?;
    exact_digits.reverse();
    let trimmed = exact_digits.iter().rposition(|&d| d != b'0').map_or(&[][..], |i| exact_digits.get(..=i).unwrap_or(&[]));
    if trimmed.len() != digits.len() + 1 || trimmed.last() != Some(&b'5') || trimmed.get(..digits.len()) != Some(digits) {
        return None;
    }
    // digits + 1 in the last place
    let n = digits.len();
    out.get_mut(..n)?.copy_from_slice(digits);
    let mut i = n;
    while i > 0 {
        i -= 1;
        let d = out.get_mut(i)?;
        if *d == b'9' {
            *d = b'0';
        } else {
            *d += 1;
            return Some((n, false));
        }
    }
    // every digit carried: 1 followed by n zeros (the trailing zeros are dropped)
    out[0] = b'1';
    Some((1, true))
}

#[cfg(test)]
mod tests {
    use super::push_f32;

    #[test]
    fn the_same_text_as_debug_on_23_million_values() {
        let mut ryu = ryu::Buffer::new();
        let mut s = String::new();
        let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut mismatches = Vec::new();
        // every exponent and sign with 2^15 mantissas each, then random patterns
        for i in 0..20_000_000u64 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let bits = if i < 1 << 17 { ((i as u32) << 15) | (x as u32 & 0x7fff) } else { x as u32 };
            let v = f32::from_bits(bits);
            s.clear();
            push_f32(&mut s, v, &mut ryu);
            let want = format!("{v:?}");
            if s != want && mismatches.len() < 10 {
                mismatches.push(format!("{bits:#010x}: {s} != {want}"));
            }
        }
        // short exact expansions, where two shortest candidates can tie: k / 2^j
        for j in 0..=40 {
            for k in 1..=70_000u32 {
                let v = -(k as f32) / (1u64 << j) as f32;
                s.clear();
                push_f32(&mut s, v, &mut ryu);
                let want = format!("{v:?}");
                if s != want && mismatches.len() < 20 {
                    mismatches.push(format!("{k}/2^{j}: {s} != {want}"));
                }
            }
        }
        for v in [
            0.0f32,
            -0.0,
            1.0,
            -1.0,
            1e-4,
            9.999999e-5,
            1e16,
            9.999999e15,
            f32::MIN_POSITIVE,
            f32::MAX,
            f32::NAN,
            f32::INFINITY,
            -f32::INFINITY,
        ] {
            s.clear();
            push_f32(&mut s, v, &mut ryu);
            if s != format!("{v:?}") {
                mismatches.push(format!("{v:?}: {s}"));
            }
        }
        assert!(mismatches.is_empty(), "{mismatches:#?}");
    }
}
