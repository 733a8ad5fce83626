//! `{token}` templates filled by a plain replacer.
//!
//! Machine profiles are data a user can edit, so their templates are never
//! evaluated: a template is literal text with `{name}` placeholders, and
//! `{{` / `}}` stand for literal braces (house style, after Kiri:Moto).

/// Why a template cannot be filled.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum TemplateError {
    /// `{name}` where `name` is not a token of this template.
    UnknownToken(String),
    /// A `{` with no `}` after it (or another `{` before it).
    UnclosedBrace,
    /// A lone `}` (write `}}` for a literal brace).
    StrayCloseBrace,
}

/// Replaces every `{token}` in `template` by `lookup(token)`.
pub(crate) fn fill(
    template: &str,
    lookup: impl Fn(&str) -> Option<String>,
) -> Result<String, TemplateError> {
    let mut out = String::with_capacity(template.len() + 16);
    let mut rest = template;
    // Braces are ASCII, so every index found below is a char boundary.
    while let Some(pos) = rest.find(['{', '}']) {
        out.push_str(&rest[..pos]);
        let tail = &rest[pos..];
        if let Some(after) = tail.strip_prefix("{{") {
            out.push('{');
            rest = after;
        } else if let Some(after) = tail.strip_prefix("}}") {
            out.push('}');
            rest = after;
        } else if let Some(body) = tail.strip_prefix('{') {
            let close = body.find('}').ok_or(TemplateError::UnclosedBrace)?;
            let token = &body[..close];
            if token.contains('{') {
                return Err(TemplateError::UnclosedBrace);
            }
            let value = lookup(token).ok_or_else(|| TemplateError::UnknownToken(token.into()))?;
            out.push_str(&value);
            rest = &body[close + 1..];
        } else {
            return Err(TemplateError::StrayCloseBrace);
        }
    }
    out.push_str(rest);
    Ok(out)
}

/// Checks that `template` only uses tokens from `known`, so that a profile
/// fails when it is loaded rather than halfway through writing a program.
pub(crate) fn check(template: &str, known: &[&str]) -> Result<(), TemplateError> {
    fill(template, |t| known.contains(&t).then(String::new)).map(|_| ())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn values(token: &str) -> Option<String> {
        match token {
            "ms" => Some("500".into()),
            "s" => Some("0.500".into()),
            _ => None,
        }
    }

    #[test]
    fn fills_tokens_and_keeps_the_rest_verbatim() {
        assert_eq!(fill("G4 P{ms}", values).unwrap(), "G4 P500");
        assert_eq!(fill("DWELL {s}", values).unwrap(), "DWELL 0.500");
        assert_eq!(fill("{s}{ms}{s}", values).unwrap(), "0.5005000.500");
        assert_eq!(fill("$DO[0].X = 1", values).unwrap(), "$DO[0].X = 1");
        assert_eq!(fill("", values).unwrap(), "");
        assert_eq!(fill("µ {ms} ü", values).unwrap(), "µ 500 ü");
    }

    #[test]
    fn doubled_braces_are_literal() {
        assert_eq!(fill("{{ms}} {ms}", values).unwrap(), "{ms} 500");
        assert_eq!(fill("a}}b", values).unwrap(), "a}b");
    }

    #[test]
    fn a_filled_value_is_not_filled_again() {
        let v = |t: &str| (t == "a").then(|| "{b}".to_string());
        assert_eq!(fill("{a}", v).unwrap(), "{b}");
    }

    #[test]
    fn unknown_and_malformed_tokens_are_errors() {
        assert_eq!(
            fill("G4 P{msec}", values),
            Err(TemplateError::UnknownToken("msec".into()))
        );
        assert_eq!(
            fill("{ ms }", values),
            Err(TemplateError::UnknownToken(" ms ".into()))
        );
        assert_eq!(fill("G4 P{ms", values), Err(TemplateError::UnclosedBrace));
        assert_eq!(fill("{a{ms}", values), Err(TemplateError::UnclosedBrace));
        assert_eq!(fill("G4 Pms}", values), Err(TemplateError::StrayCloseBrace));
    }

    #[test]
    fn check_accepts_known_tokens_only() {
        assert!(check("G4 P{ms}", &["ms", "s"]).is_ok());
        assert_eq!(
            check("G4 P{ms}", &["s"]),
            Err(TemplateError::UnknownToken("ms".into()))
        );
    }
}
