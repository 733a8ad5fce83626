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
    let text = format!("{:.*}", decimals as usize, value);
    match text.strip_prefix('-') {
        Some(magnitude) if magnitude.bytes().all(|b| b == b'0' || b == b'.') => magnitude.into(),
        _ => text,
    }
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
