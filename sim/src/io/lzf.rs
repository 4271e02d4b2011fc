//! LZF decompression (the format of PCD `DATA binary_compressed`), with every read and
//! back-reference bounds-checked: corrupt input gives an error message, never a panic.

/// Decompresses LZF `input` into exactly `out_len` bytes, or says what is wrong.
pub(crate) fn decompress(input: &[u8], out_len: usize) -> Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(out_len);
    let mut ip = 0;
    while ip < input.len() {
        let ctrl = usize::from(input[ip]);
        ip += 1;
        if ctrl < 32 {
            let run = ctrl + 1;
            let lit = input.get(ip..ip + run).ok_or("LZF literal run past the end of the data")?;
            if out.len() + run > out_len {
                return Err("LZF data expands past the declared size".into());
            }
            out.extend_from_slice(lit);
            ip += run;
        } else {
            let mut len = ctrl >> 5;
            if len == 7 {
                len += usize::from(*input.get(ip).ok_or("LZF length byte missing")?);
                ip += 1;
            }
            let low = usize::from(*input.get(ip).ok_or("LZF offset byte missing")?);
            ip += 1;
            let back = ((ctrl & 0x1f) << 8) + low + 1;
            let start = out.len().checked_sub(back).ok_or("LZF back-reference before the start of the data")?;
            let len = len + 2;
            if out.len() + len > out_len {
                return Err("LZF data expands past the declared size".into());
            }
            // Byte by byte: the source may overlap what is being written.
            for k in 0..len {
                let b = out[start + k];
                out.push(b);
            }
        }
    }
    if out.len() != out_len {
        return Err(format!("LZF data expands to {} bytes, header declares {out_len}", out.len()));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn literal_and_overlapping_back_reference() {
        // "abc" as a literal, then a back-reference of length 6 at distance 3: "abcabcabc".
        let input = [2, b'a', b'b', b'c', (4 << 5), 2];
        assert_eq!(decompress(&input, 9).unwrap(), b"abcabcabc");
        assert!(decompress(&input, 8).is_err(), "declared size too small");
        assert!(decompress(&[(1 << 5), 5], 3).is_err(), "reference before the start");
        assert!(decompress(&[5, 1, 2], 6).is_err(), "truncated literal");
    }
}
