//! Checksums of the formats talus writes: the CRC-32 of saved states and checkpoints
//! (crc32fast; zip and png compute their own), and the FNV-1a fingerprint of scenes.

/// CRC-32 (IEEE 802.3, reflected: the one zip and PNG use), from `crc32fast`.
pub fn crc32(data: &[u8]) -> u32 {
    crc32fast::hash(data)
}

/// FNV-1a, 64 bits, from `seed` (0xcbf2_9ce4_8422_2325 is the standard offset): a
/// fingerprint stable across Rust versions and platforms, which `std`'s hashers are
/// not. Three lines, so no crate.
pub fn fnv1a(bytes: &[u8], seed: u64) -> u64 {
    bytes
        .iter()
        .fold(seed, |h, b| (h ^ *b as u64).wrapping_mul(0x0100_0000_01b3))
}

/// The standard FNV-1a offset basis.
pub const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn standard_check_values() {
        // The CRC-32 check value of the catalogue of parametrised CRCs, and FNV-1a's
        // published test vectors.
        assert_eq!(crc32(b"123456789"), 0xcbf4_3926);
        assert_eq!(crc32(b""), 0);
        assert_eq!(fnv1a(b"", FNV_OFFSET), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a(b"a", FNV_OFFSET), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a(b"foobar", FNV_OFFSET), 0x8594_4171_f739_67e8);
    }
}
