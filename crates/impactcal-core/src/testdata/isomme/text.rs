//! Decoding ISO-MME text and splitting it into header fields and sample lines.

/// The text encoding a file was found to use. ISO-MME files carry no declaration, so it is
/// recovered from the bytes: a UTF-8 byte order mark or valid UTF-8 means UTF-8 (plain ASCII
/// when every byte is below 0x80); anything else is single-byte Western text, Windows-1252
/// when it uses the bytes 0x80-0x9F that Windows-1252 defines and ISO-8859-1 leaves as control
/// codes, ISO-8859-1 otherwise (the two agree on every other byte).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub enum TextEncoding {
    /// 7-bit ASCII.
    #[serde(rename = "ASCII")]
    Ascii,
    /// UTF-8, with or without a byte order mark.
    #[serde(rename = "UTF-8")]
    Utf8,
    /// ISO-8859-1 (Latin-1).
    #[serde(rename = "ISO-8859-1")]
    Latin1,
    /// Windows-1252.
    #[serde(rename = "Windows-1252")]
    Windows1252,
}

impl std::fmt::Display for TextEncoding {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            TextEncoding::Ascii => "ASCII",
            TextEncoding::Utf8 => "UTF-8",
            TextEncoding::Latin1 => "ISO-8859-1",
            TextEncoding::Windows1252 => "Windows-1252",
        })
    }
}

/// Windows-1252's characters for the bytes 0x80-0x9F; the five bytes it leaves undefined
/// (0x81, 0x8D, 0x8F, 0x90, 0x9D) keep their ISO-8859-1 meaning.
const CP1252_HIGH: [char; 32] = [
    '€', '\u{81}', '‚', 'ƒ', '„', '…', '†', '‡', 'ˆ', '‰', 'Š', '‹', 'Œ', '\u{8d}', 'Ž', '\u{8f}',
    '\u{90}', '‘', '’', '“', '”', '•', '–', '—', '˜', '™', 'š', '›', 'œ', '\u{9d}', 'ž', 'Ÿ',
];

/// Decodes the bytes of one file, returning the text and the encoding found.
pub(crate) fn decode(bytes: &[u8]) -> (String, TextEncoding) {
    let body = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes);
    if let Ok(text) = std::str::from_utf8(body) {
        let encoding = if body.is_ascii() && body.len() == bytes.len() {
            TextEncoding::Ascii
        } else {
            TextEncoding::Utf8
        };
        return (text.to_string(), encoding);
    }
    let mut windows = false;
    let text = body
        .iter()
        .map(|&b| match b {
            0x80..=0x9f => {
                let c = CP1252_HIGH[usize::from(b - 0x80)];
                windows |= u32::from(c) > 0xff;
                c
            }
            _ => char::from(b),
        })
        .collect();
    let encoding = if windows {
        TextEncoding::Windows1252
    } else {
        TextEncoding::Latin1
    };
    (text, encoding)
}

/// One `name : value` header line.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Field {
    pub name: String,
    /// The value, trimmed; `None` for an empty value or `NOVALUE`.
    pub value: Option<String>,
    /// 1-based line number.
    pub line: usize,
}

/// Splits a header line `name : value` at its first colon. A line is a header line when the
/// text before the first colon is non-empty (names hold no colon; values may).
pub(crate) fn field(line: &str, number: usize) -> Option<Field> {
    let (name, value) = line.split_once(':')?;
    let name = name.trim();
    if name.is_empty() {
        return None;
    }
    let value = value.trim();
    let value =
        (!value.is_empty() && !value.eq_ignore_ascii_case("NOVALUE")).then(|| value.to_string());
    Some(Field {
        name: name.to_string(),
        value,
        line: number,
    })
}

/// The lines of a text with their 1-based numbers, line ends (`\n`, `\r\n`) removed.
pub(crate) fn numbered_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.split('\n')
        .enumerate()
        .map(|(i, l)| (i + 1, l.strip_suffix('\r').unwrap_or(l)))
}

#[cfg(test)]
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;

    #[test]
    fn encodings_are_recognised() {
        assert_eq!(decode(b"Unit :g\n").1, TextEncoding::Ascii);
        let utf8 = "Laboratory name :Prüfstand Köln\n";
        assert_eq!(
            decode(utf8.as_bytes()),
            (utf8.to_string(), TextEncoding::Utf8)
        );
        let bom = [b"\xef\xbb\xbf".as_slice(), b"Unit :g"].concat();
        assert_eq!(decode(&bom), ("Unit :g".to_string(), TextEncoding::Utf8));
        // "Prüfstand µm" in ISO-8859-1.
        let latin = b"Pr\xfcfstand \xb5m";
        assert_eq!(
            decode(latin),
            ("Prüfstand µm".to_string(), TextEncoding::Latin1)
        );
        // "25 € … ™" in Windows-1252.
        let cp = b"25 \x80 \x85 \x99";
        assert_eq!(
            decode(cp),
            ("25 € … ™".to_string(), TextEncoding::Windows1252)
        );
    }

    #[test]
    fn header_fields_split_at_the_first_colon() {
        let f = field("Time of test    :10:32:45", 3).unwrap();
        assert_eq!(
            (f.name.as_str(), f.value.as_deref(), f.line),
            ("Time of test", Some("10:32:45"), 3)
        );
        assert_eq!(field("Transducer type :NOVALUE", 1).unwrap().value, None);
        assert_eq!(field("Regulation      :   ", 1).unwrap().value, None);
        assert!(field("-6.774550E-4", 1).is_none());
        assert!(field(":x", 1).is_none());
    }
}
