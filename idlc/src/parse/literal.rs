//! Literal values: integers in three bases, floats, fixed-point, characters and strings with escapes.

/// Parses an integer literal (decimal, `0x` hex, leading-`0` octal).
pub fn parse_int(s: &str) -> Result<u128, String> {
    let (digits, radix) = if let Some(h) = s.strip_prefix("0x").or_else(|| s.strip_prefix("0X")) {
        (h, 16)
    } else if s.len() > 1 && s.starts_with('0') {
        (&s[1..], 8)
    } else {
        (s, 10)
    };
    if radix == 8 && digits.bytes().any(|b| b > b'7') {
        return Err(format!(
            "`{s}` is not a valid octal literal (a leading 0 means octal)"
        ));
    }
    if digits.len() > 64 {
        return Err("integer literal is too large for any IDL integer type".into());
    }
    u128::from_str_radix(digits, radix)
        .ok()
        .filter(|v| *v <= u64::MAX as u128)
        .ok_or_else(|| {
            "integer literal is too large for any IDL integer type (max 2^64-1)".to_string()
        })
}

/// Resolves the escapes of a char or string literal body.
pub fn unescape(s: &str) -> Result<String, String> {
    let mut out = String::with_capacity(s.len());
    let mut it = s.chars().peekable();
    while let Some(c) = it.next() {
        if c != '\\' {
            out.push(c);
            continue;
        }
        let e = it.next().ok_or("dangling `\\` at the end of a literal")?;
        let v = match e {
            'n' => '\n',
            't' => '\t',
            'v' => '\x0B',
            'b' => '\x08',
            'r' => '\r',
            'f' => '\x0C',
            'a' => '\x07',
            '\\' | '?' | '\'' | '"' => e,
            '0'..='7' => {
                let mut v = e.to_digit(8).unwrap_or(0);
                for _ in 0..2 {
                    match it.peek().and_then(|c| c.to_digit(8)) {
                        Some(d) => {
                            v = v * 8 + d;
                            it.next();
                        }
                        None => break,
                    }
                }
                char::from_u32(v).ok_or("invalid octal escape")?
            }
            'x' | 'X' | 'u' | 'U' => {
                let max = if e.eq_ignore_ascii_case(&'x') { 2 } else { 4 };
                let mut v = 0u32;
                let mut n = 0;
                while n < max {
                    match it.peek().and_then(|c| c.to_digit(16)) {
                        Some(d) => {
                            v = v * 16 + d;
                            it.next();
                            n += 1;
                        }
                        None => break,
                    }
                }
                if n == 0 {
                    return Err(format!("`\\{e}` needs hexadecimal digits"));
                }
                char::from_u32(v).ok_or("escape is not a valid character")?
            }
            other => return Err(format!("unknown escape `\\{other}`")),
        };
        out.push(v);
    }
    Ok(out)
}
