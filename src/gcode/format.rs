//! Number and comment text as controllers read them.
//!
//! Spec section 9: numbers are finite and fixed-precision. Rust's `{:.N}`
//! never uses exponent notation and rounds the exact binary value the same
//! way on every platform (wasm32 included), so programs are reproducible
//! byte for byte; the only fix needed is `-0.000`, which some controllers
//! reject and which would make golden files depend on rounding noise.

use super::profile::CommentStyle;

/// `value` with exactly `decimals` digits after the point, never `-0.000`.
/// The caller has checked that `value` is finite.
pub(crate) fn fixed(value: f64, decimals: u32) -> String {
    let mut text = String::with_capacity(24);
    push_fixed(&mut text, value, decimals);
    text
}

/// [`fixed`] appended to `out`, returning the value a controller reads
/// from it ([`read_back`]): the writer does both for every coordinate of
/// every move, and they share the scaling (issue 15).
pub(crate) fn push_fixed(out: &mut String, value: f64, decimals: u32) -> f64 {
    let Some((negative, q)) = scaled(value, decimals) else {
        let text = fixed_by_format(value, decimals);
        out.push_str(&text);
        return text.parse().unwrap_or(value);
    };
    let negative = negative && q != 0;
    if negative {
        out.push('-');
    }
    // The digits of q from the last, with the point before the last
    // `decimals` of them and at least one digit before it (q < 2^53: 16
    // digits at most, and the point).
    let mut digits = [0u8; 24];
    let mut i = digits.len();
    let (mut rest, mut k) = (q, 0);
    loop {
        if decimals > 0 && k == decimals {
            i -= 1;
            digits[i] = b'.';
        }
        i -= 1;
        digits[i] = b'0' + (rest % 10) as u8;
        rest /= 10;
        k += 1;
        if rest == 0 && k > decimals {
            break;
        }
    }
    for &b in &digits[i..] {
        out.push(char::from(b));
    }
    unscaled(negative, q, decimals)
}

/// The f64 nearest to the text [`scaled`]'s (sign, magnitude) stands for:
/// q < 2^53 and the power of ten are exact, and IEEE division rounds the
/// exact quotient to the nearest f64, as parsing does.
fn unscaled(negative: bool, q: u64, decimals: u32) -> f64 {
    let v = q as f64 / POW10[decimals as usize];
    if negative && q != 0 {
        -v
    } else {
        v
    }
}

/// [`fixed`] through `{:.N}`, for what [`scaled`] does not take.
fn fixed_by_format(value: f64, decimals: u32) -> String {
    let text = format!("{:.*}", decimals as usize, value);
    match text.strip_prefix('-') {
        Some(magnitude) if magnitude.bytes().all(|b| b == b'0' || b == b'.') => magnitude.into(),
        _ => text,
    }
}

/// The value a controller reads from [`fixed`]'s text: the f64 nearest
/// it, as parsing the text gives (issue 15: the writer reads back every
/// coordinate it writes, and formatting and parsing each cost more than
/// the rest of writing the move).
pub(crate) fn read_back(value: f64, decimals: u32) -> f64 {
    match scaled(value, decimals) {
        Some((negative, q)) => unscaled(negative, q, decimals),
        None => fixed_by_format(value, decimals).parse().unwrap_or(value),
    }
}

/// 10^k, exact in f64.
const POW10: [f64; 10] = [1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9];

/// `value` times 10^`decimals`, rounded to an integer as `{:.N}` rounds:
/// the exact binary value, ties to even; as (sign, magnitude). `None`
/// past 9 decimals, for non-finite values, and where the magnitude
/// reaches 2^53 (it is then left to `{:.N}`).
fn scaled(value: f64, decimals: u32) -> Option<(bool, u64)> {
    if decimals as usize >= POW10.len() || !value.is_finite() {
        return None;
    }
    let bits = value.to_bits();
    let negative = bits >> 63 == 1;
    let exp = ((bits >> 52) & 0x7ff) as i32;
    let frac = bits & ((1 << 52) - 1);
    // |value| = m 2^e exactly.
    let (m, e) = if exp == 0 {
        (frac, -1074)
    } else {
        (frac | 1 << 52, exp - 1075)
    };
    // m 10^d < 2^53 2^30.
    let n = u128::from(m) * 10u128.pow(decimals);
    let q = if e >= 0 {
        if e > 20 {
            return None;
        }
        n << e
    } else if e <= -100 {
        // n < 2^83 lies below half of 2^-e: rounds to 0.
        0
    } else {
        let s = (-e) as u32;
        let (q, r, half) = (n >> s, n & ((1 << s) - 1), 1u128 << (s - 1));
        if r > half || (r == half && q & 1 == 1) {
            q + 1
        } else {
            q
        }
    };
    u64::try_from(q)
        .ok()
        .filter(|&q| q < 1 << 53)
        .map(|q| (negative, q))
}

/// Like [`fixed`] with trailing zeros dropped (`F300`, `F2.5`): feeds are
/// read by people comparing against the paper's "5 mm/s = F300".
pub(crate) fn trimmed(value: f64, decimals: u32) -> String {
    let text = fixed(value, decimals);
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').into()
    } else {
        text
    }
}

/// One comment line in the profile's style, e.g. `; text` or `( text )`.
pub(crate) fn comment_line(style: &CommentStyle, text: &str) -> String {
    let text = sanitize_comment(style, text);
    match (style.suffix.is_empty(), text.is_empty()) {
        (true, true) => style.prefix.clone(),
        (true, false) => format!("{} {}", style.prefix, text),
        (false, true) => format!("{}{}", style.prefix, style.suffix),
        (false, false) => format!("{} {} {}", style.prefix, text, style.suffix),
    }
}

/// Makes `text` safe inside one comment: header values come from users and
/// files, and must not end the comment and smuggle in a command.
///
/// - Line breaks and other control characters become spaces (a newline
///   would start a new, executed line).
/// - Non-ASCII becomes `?`: controllers read bytes, and some firmware
///   rejects or mangles high bytes even inside comments.
/// - In comments closed by a suffix (`( )`), characters of the prefix and
///   suffix are replaced (`(` `)` become `[` `]`) because Grbl and LinuxCNC
///   do not nest parentheses, and commas become spaces because LinuxCNC
///   treats `(MSG,` `(DEBUG,` `(LOGOPEN,` ... as active comments.
pub(crate) fn sanitize_comment(style: &CommentStyle, text: &str) -> String {
    let closed = !style.suffix.is_empty();
    let delimiter = |c: char| style.prefix.contains(c) || style.suffix.contains(c);
    let clean: String = text
        .chars()
        .map(|c| match c {
            c if c.is_control() => ' ',
            c if !c.is_ascii() => '?',
            '(' if closed && delimiter(c) => '[',
            ')' if closed && delimiter(c) => ']',
            ',' if closed => ' ',
            c if closed && delimiter(c) => '_',
            c => c,
        })
        .collect();
    clean.trim().into()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn style(prefix: &str, suffix: &str) -> CommentStyle {
        CommentStyle {
            prefix: prefix.into(),
            suffix: suffix.into(),
        }
    }

    #[test]
    fn fixed_and_push_fixed_write_and_read_back_what_format_and_parse_give() {
        let mut bits = crate::demo::workloads::Rng(0x9e37_79b9_7f4a_7c15);
        let mut values = vec![
            0.0, -0.0, 0.5, 1.5, 2.5, -2.5, 1e-320, -5e-324, 9.0e15, 1.0e16,
        ];
        // Exact ties at every decimal count: j / 2^k with small k.
        for j in -300..300 {
            for k in 0..12 {
                values.push(j as f64 / (1u64 << k) as f64);
            }
        }
        for _ in 0..60_000 {
            let b = bits.next_u64();
            // Coordinates in mm, large values, tiny ones and any bits.
            values.push((b >> 11) as f64 / (1u64 << 53) as f64 * 400.0 - 200.0);
            values.push(f64::from_bits(b) % 1e13);
            values.push(f64::from_bits(b >> 2));
        }
        for v in values.into_iter().filter(|v| v.is_finite()) {
            for d in [0, 1, 3, 4, 6, 9, 12] {
                let want = fixed_by_format(v, d);
                assert_eq!(fixed(v, d), want, "{v:e} at {d} decimals");
                let back: f64 = want.parse().unwrap();
                assert_eq!(read_back(v, d).to_bits(), back.to_bits(), "{v:e} at {d}");
                // Appended after what the line holds, with the value read back.
                let mut line = String::from("G1 X");
                let pushed = push_fixed(&mut line, v, d);
                assert_eq!(line, format!("G1 X{want}"), "{v:e} at {d}");
                assert_eq!(pushed.to_bits(), back.to_bits(), "{v:e} at {d}");
            }
        }
    }

    #[test]
    fn fixed_precision_without_negative_zero_or_exponent() {
        assert_eq!(fixed(1.0, 3), "1.000");
        assert_eq!(fixed(-0.0, 3), "0.000");
        assert_eq!(fixed(-0.0004, 3), "0.000");
        assert_eq!(fixed(-0.0005001, 3), "-0.001");
        assert_eq!(fixed(-12.5, 3), "-12.500");
        assert_eq!(fixed(1e-9, 4), "0.0000");
        assert_eq!(fixed(1e-12, 6), "0.000000");
        assert_eq!(fixed(123456.789, 3), "123456.789");
        assert_eq!(fixed(1e15, 3), "1000000000000000.000");
        assert_eq!(fixed(-0.0, 0), "0");
        assert_eq!(fixed(499.6, 0), "500");
        for v in [1e-300, -1e-300, 1e-7, 3.0e10, -7.25e-5] {
            let t = fixed(v, 3);
            assert!(!t.contains(['e', 'E']), "{t}");
            assert_ne!(t, "-0.000");
        }
    }

    #[test]
    fn feeds_drop_trailing_zeros() {
        assert_eq!(trimmed(300.0, 3), "300");
        assert_eq!(trimmed(5.0, 3), "5");
        assert_eq!(trimmed(2.5, 3), "2.5");
        assert_eq!(trimmed(20.0 / 3.0, 3), "6.667");
        assert_eq!(trimmed(-0.0, 3), "0");
        assert_eq!(trimmed(1000.0, 3), "1000");
    }

    #[test]
    fn comments_cannot_break_the_line() {
        let semi = style(";", "");
        assert_eq!(comment_line(&semi, "a\nG1 X0\r\nb"), "; a G1 X0  b");
        assert_eq!(comment_line(&semi, "tab\there"), "; tab here");
        assert_eq!(comment_line(&semi, "µm ±"), "; ?m ?");
        assert_eq!(comment_line(&semi, ""), ";");
        assert_eq!(comment_line(&style("'", ""), "it's"), "' it's");
    }

    #[test]
    fn parenthesized_comments_do_not_nest_and_are_not_active() {
        let paren = style("(", ")");
        assert_eq!(
            comment_line(&paren, "f(x) = (a)) G0 Z0"),
            "( f[x] = [a]] G0 Z0 )"
        );
        assert_eq!(comment_line(&paren, "MSG,hello"), "( MSG hello )");
        assert_eq!(comment_line(&paren, "\n"), "()");
        // Semicolons stay: inside parentheses they are plain text.
        assert_eq!(comment_line(&paren, "a;b"), "( a;b )");
        // Any other delimiter characters are replaced too.
        assert_eq!(comment_line(&style("/*", "*/"), "a */ b"), "/* a __ b */");
    }
}
