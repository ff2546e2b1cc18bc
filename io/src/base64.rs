//! The one base64 decoder: a lenient, streaming one, as VTK's XML files need.

/// Why taking bytes from a stream failed.
#[derive(Debug, PartialEq, Eq)]
pub(crate) enum TakeError {
    /// The data ended after `found` of the requested bytes.
    Short { found: usize },
    /// The base64 text is invalid.
    BadBase64(String),
}

/// Decodes base64 text on demand: skips whitespace and accepts `=` padding at the end of
/// any 4-character group, because VTK may encode a block header and the data that
/// follows it as separate base64 streams.
pub(crate) struct Base64<'a> {
    text: &'a [u8],
    pos: usize,
    pending: Vec<u8>,
}

fn value(c: u8) -> Option<u8> {
    match c {
        b'A'..=b'Z' => Some(c - b'A'),
        b'a'..=b'z' => Some(c - b'a' + 26),
        b'0'..=b'9' => Some(c - b'0' + 52),
        b'+' => Some(62),
        b'/' => Some(63),
        _ => None,
    }
}

impl<'a> Base64<'a> {
    pub fn new(text: &'a [u8]) -> Self {
        Base64 {
            text,
            pos: 0,
            pending: Vec::new(),
        }
    }

    /// The next `n` decoded bytes.
    pub fn take(&mut self, n: usize) -> Result<Vec<u8>, TakeError> {
        // `n` comes from the file: reserve no more than the text can hold.
        let mut out = Vec::with_capacity(n.min(self.text.len() / 4 * 3 + 3));
        let from_pending = n.min(self.pending.len());
        out.extend(self.pending.drain(..from_pending));
        while out.len() < n {
            let mut quad = [0u8; 4];
            let mut k = 0;
            while k < 4 {
                match self.text.get(self.pos) {
                    None => break,
                    Some(c) if c.is_ascii_whitespace() => self.pos += 1,
                    Some(&c) => {
                        quad[k] = c;
                        k += 1;
                        self.pos += 1;
                    }
                }
            }
            if k < 4 {
                // End of the text (a partial group means the text was cut off).
                return Err(TakeError::Short { found: out.len() });
            }
            let bad_char = |c: u8| {
                TakeError::BadBase64(format!(
                    "invalid base64 character {:?} near text offset {}",
                    c as char,
                    self.pos.saturating_sub(1)
                ))
            };
            let v0 = value(quad[0]).ok_or_else(|| bad_char(quad[0]))?;
            let v1 = value(quad[1]).ok_or_else(|| bad_char(quad[1]))?;
            let mut group = [0u8; 3];
            group[0] = (v0 << 2) | (v1 >> 4);
            let len = match (quad[2], quad[3]) {
                (b'=', b'=') => 1,
                (c2, b'=') => {
                    let v2 = value(c2).ok_or_else(|| bad_char(c2))?;
                    group[1] = (v1 << 4) | (v2 >> 2);
                    2
                }
                (c2, c3) => {
                    let v2 = value(c2).ok_or_else(|| bad_char(c2))?;
                    let v3 = value(c3).ok_or_else(|| bad_char(c3))?;
                    group[1] = (v1 << 4) | (v2 >> 2);
                    group[2] = (v2 << 6) | v3;
                    3
                }
            };
            for &b in &group[..len] {
                if out.len() < n {
                    out.push(b);
                } else {
                    self.pending.push(b);
                }
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use base64::Engine;

    fn encode(d: &[u8]) -> String {
        base64::engine::general_purpose::STANDARD.encode(d)
    }

    #[test]
    fn decodes_what_a_reference_encoder_writes() {
        let data: Vec<u8> = (0..=255u8)
            .chain((0..100u8).map(|i| i.wrapping_mul(7)))
            .collect();
        for len in [0, 1, 2, 3, 4, 5, 64, data.len()] {
            let text = encode(&data[..len]);
            // Taken in pieces of every size, across group boundaries.
            for piece in [1, 2, 3, 5, 64] {
                let mut b = Base64::new(text.as_bytes());
                let mut got = Vec::new();
                while got.len() < len {
                    let n = piece.min(len - got.len());
                    got.extend(b.take(n).unwrap());
                }
                assert_eq!(got, data[..len], "length {len}, pieces of {piece}");
            }
        }
    }

    #[test]
    fn separately_padded_streams_and_whitespace() {
        let text = format!("{}\n  {}", encode(&[1, 2, 3, 4]), encode(&[5, 6]));
        let mut b = Base64::new(text.as_bytes());
        assert_eq!(b.take(6).unwrap(), vec![1, 2, 3, 4, 5, 6]);
        assert_eq!(b.take(1), Err(TakeError::Short { found: 0 }));
    }

    #[test]
    fn reports_bad_characters_and_short_text() {
        let mut b = Base64::new(b"AAE*");
        assert!(matches!(b.take(3), Err(TakeError::BadBase64(m)) if m.contains("'*'")));
        let mut b = Base64::new(b"AAECAw");
        assert_eq!(b.take(4), Err(TakeError::Short { found: 3 }));
    }
}
