//! The `.ray` format's tokens: numbers, words, punctuation and strings, with `//` and
//! `/* */` comments skipped.

use crate::diagnostics::SceneError;
use std::ops::Range;
use std::path::Path;

#[derive(Clone, Debug, PartialEq)]
pub(super) enum Tok {
    Num(f64),
    Word(String),
    Str(String),
    Punct(char),
}

/// Tokens with their byte spans.
pub(super) fn lex(path: &Path, text: &str) -> Result<Vec<(Tok, Range<usize>)>, SceneError> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c.is_ascii_whitespace() {
            i += 1;
        } else if b[i..].starts_with(b"//") {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i..].starts_with(b"/*") {
            let end = text[i + 2..]
                .find("*/")
                .ok_or_else(|| SceneError::at(path, text, i..i + 2, "unterminated comment"))?;
            i += end + 4;
        } else if c.is_ascii_digit()
            || c == b'.'
            || ((c == b'-' || c == b'+')
                && i + 1 < b.len()
                && (b[i + 1].is_ascii_digit() || b[i + 1] == b'.'))
        {
            let start = i;
            i += 1;
            while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'.') {
                i += 1;
            }
            if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
                i += 1;
                if i < b.len() && (b[i] == b'-' || b[i] == b'+') {
                    i += 1;
                }
                while i < b.len() && b[i].is_ascii_digit() {
                    i += 1;
                }
            }
            let s = &text[start..i];
            let v: f64 = s.parse().map_err(|_| {
                SceneError::at(
                    path,
                    text,
                    start..i,
                    format!("expected a number, found `{s}`"),
                )
            })?;
            if !v.is_finite() {
                return Err(SceneError::at(
                    path,
                    text,
                    start..i,
                    format!("expected a finite number, found `{s}`"),
                ));
            }
            out.push((Tok::Num(v), start..i));
        } else if c.is_ascii_alphabetic() || c == b'_' {
            let start = i;
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_' || b[i] == b'-') {
                i += 1;
            }
            out.push((Tok::Word(text[start..i].to_string()), start..i));
        } else if c == b'"' {
            let start = i;
            let end = text[i + 1..].find(['"', '\n']).map(|e| i + 1 + e);
            match end {
                Some(e) if b[e] == b'"' => {
                    out.push((Tok::Str(text[i + 1..e].to_string()), start..e + 1));
                    i = e + 1;
                }
                _ => {
                    return Err(SceneError::at(
                        path,
                        text,
                        start..start + 1,
                        "unterminated string",
                    ))
                }
            }
        } else if b"(){},=;".contains(&c) {
            out.push((Tok::Punct(c as char), i..i + 1));
            i += 1;
        } else {
            let ch = text[i..].chars().next().unwrap_or('?');
            return Err(SceneError::at(
                path,
                text,
                i..i + ch.len_utf8(),
                format!("unexpected character `{ch}`"),
            ));
        }
    }
    Ok(out)
}
