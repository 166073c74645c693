//! Sizes in bytes as users write them (`--max-memory 2G`).

/// Parses `<number>[unit]`: a number of bytes, or with `K`, `M`, `G` or `T` (powers of
/// 1024, case-insensitive, optionally followed by `B` or `iB`): `1500000000`, `512M`, `2G`,
/// `1.5GiB`. Fractions are allowed with a unit.
///
/// # Errors
/// A message naming the text when it is not such a size, or is zero.
pub fn parse_bytes(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let lower = t.to_ascii_lowercase();
    let body = lower
        .strip_suffix("ib")
        .or_else(|| lower.strip_suffix('b'))
        .unwrap_or(&lower);
    let (number, factor) = match body.chars().last() {
        Some('k') => (&body[..body.len() - 1], 1u64 << 10),
        Some('m') => (&body[..body.len() - 1], 1 << 20),
        Some('g') => (&body[..body.len() - 1], 1 << 30),
        Some('t') => (&body[..body.len() - 1], 1 << 40),
        _ => (body, 1),
    };
    let bad =
        || format!("`{t}` is not a size: give bytes or a number with K, M, G or T (2G, 512M)");
    let value: f64 = number.trim().parse().map_err(|_| bad())?;
    let bytes = value * factor as f64;
    if !(bytes.is_finite() && (1.0..1.8e19).contains(&bytes)) {
        return Err(bad());
    }
    Ok(bytes as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_with_binary_units_and_bad_ones_are_named() {
        assert_eq!(parse_bytes("1500000000"), Ok(1_500_000_000));
        assert_eq!(parse_bytes("512M"), Ok(512 << 20));
        assert_eq!(parse_bytes("2G"), Ok(2 << 30));
        assert_eq!(parse_bytes("2gb"), Ok(2 << 30));
        assert_eq!(parse_bytes("1.5GiB"), Ok(3 << 29));
        assert_eq!(parse_bytes(" 64k "), Ok(64 << 10));
        for bad in ["", "G", "two G", "-1G", "0", "1e30"] {
            let e = parse_bytes(bad).unwrap_err();
            assert!(e.contains("not a size"), "{bad}: {e}");
        }
    }
}
