//! TIFF structure (Adobe, *TIFF Revision 6.0*, 1992, §2 "Image File Directory"; CIPA
//! DC-008-2016 "Exif 2.31" §4.6 for the Exif and GPS IFDs), little-endian: the container of the
//! EXIF block that JPEG and PNG embed, and of a whole baseline RGB TIFF file (one uncompressed
//! strip, 8 bits per sample) whose IFD0 points to the same Exif and GPS IFDs and holds the XMP
//! packet in tag 700 (Adobe, *XMP Specification Part 3*, 2016, §1.1.4 "TIFF").
//!
//! # Known limitations
//! Little-endian, classic TIFF only (no BigTIFF): a file must stay below 4 GiB, which holds an RGB
//! image of about 1.4 gigapixels.

/// One IFD entry: tag, type, count and the value bytes (little-endian).
#[derive(Clone, Debug)]
pub struct Entry {
    pub tag: u16,
    pub kind: u16,
    pub count: u32,
    pub bytes: Vec<u8>,
}

pub const BYTE: u16 = 1;
pub const ASCII: u16 = 2;
pub const SHORT: u16 = 3;
pub const LONG: u16 = 4;
pub const RATIONAL: u16 = 5;
pub const UNDEFINED: u16 = 7;

/// IFD0 tag of the Exif IFD pointer.
pub const EXIF_IFD_POINTER: u16 = 0x8769;
/// IFD0 tag of the GPS IFD pointer.
pub const GPS_IFD_POINTER: u16 = 0x8825;
/// IFD0 tag of the XMP packet (XMP Specification Part 3, §1.1.4).
pub const XMP_TAG: u16 = 700;

fn count_of(len: usize) -> u32 {
    u32::try_from(len).unwrap_or(u32::MAX)
}

/// An ASCII entry (non-ASCII characters dropped, NUL-terminated).
#[must_use]
pub fn ascii(tag: u16, text: &str) -> Entry {
    let mut bytes: Vec<u8> = text.bytes().filter(u8::is_ascii).collect();
    bytes.push(0);
    Entry {
        tag,
        kind: ASCII,
        count: count_of(bytes.len()),
        bytes,
    }
}

/// Unsigned rationals `|v|·denominator / denominator`.
#[must_use]
pub fn rationals(tag: u16, values: &[f64], denominator: u32) -> Entry {
    let mut bytes = Vec::new();
    for v in values {
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let n = (v.abs() * f64::from(denominator))
            .round()
            .min(f64::from(u32::MAX)) as u32;
        bytes.extend(n.to_le_bytes());
        bytes.extend(denominator.to_le_bytes());
    }
    Entry {
        tag,
        kind: RATIONAL,
        count: count_of(values.len()),
        bytes,
    }
}

/// A LONG entry.
#[must_use]
pub fn long(tag: u16, v: u32) -> Entry {
    Entry {
        tag,
        kind: LONG,
        count: 1,
        bytes: v.to_le_bytes().to_vec(),
    }
}

/// SHORT entries.
#[must_use]
pub fn shorts(tag: u16, values: &[u16]) -> Entry {
    Entry {
        tag,
        kind: SHORT,
        count: count_of(values.len()),
        bytes: values.iter().flat_map(|v| v.to_le_bytes()).collect(),
    }
}

/// Raw bytes of type `kind` (BYTE or UNDEFINED).
#[must_use]
pub fn bytes(tag: u16, kind: u16, data: &[u8]) -> Entry {
    Entry {
        tag,
        kind,
        count: count_of(data.len()),
        bytes: data.to_vec(),
    }
}

/// Appends one IFD (entries sorted by tag, values longer than 4 bytes after it) to `out`.
fn write_ifd(out: &mut Vec<u8>, entries: &mut [Entry], next_ifd: u32) {
    entries.sort_by_key(|e| e.tag);
    let start = out.len();
    let count = u16::try_from(entries.len()).unwrap_or(u16::MAX);
    let data_start = start + 2 + 12 * entries.len() + 4;
    let mut data: Vec<u8> = Vec::new();
    out.extend(count.to_le_bytes());
    for e in entries.iter() {
        out.extend(e.tag.to_le_bytes());
        out.extend(e.kind.to_le_bytes());
        out.extend(e.count.to_le_bytes());
        if e.bytes.len() <= 4 {
            let mut v = e.bytes.clone();
            v.resize(4, 0);
            out.extend(v);
        } else {
            out.extend(count_of(data_start + data.len()).to_le_bytes());
            data.extend(&e.bytes);
            if data.len() % 2 == 1 {
                data.push(0); // word alignment
            }
        }
    }
    out.extend(next_ifd.to_le_bytes());
    out.extend(data);
}

/// The metadata IFDs of a file: IFD0 entries beyond the image's, the Exif IFD and the GPS IFD
/// (empty: left out).
#[derive(Clone, Debug, Default)]
pub struct MetadataIfds {
    pub ifd0: Vec<Entry>,
    pub exif: Vec<Entry>,
    pub gps: Vec<Entry>,
}

/// An 8-bit RGB image to store in a TIFF file.
#[derive(Clone, Copy, Debug)]
pub struct RgbStrip<'a> {
    pub size_px: [u32; 2],
    /// Row-major RGB samples, `3·w·h` bytes.
    pub samples: &'a [u8],
}

/// A TIFF structure: header | IFD0 | Exif IFD | GPS IFD | (image strip). Without an image this
/// is the EXIF block JPEG (APP1, after `Exif\0\0`) and PNG (`eXIf`) embed.
#[must_use]
pub fn tiff_bytes(ifds: &MetadataIfds, image: Option<RgbStrip<'_>>) -> Vec<u8> {
    let build = |exif_at: u32, gps_at: u32, strip_at: u32| -> (Vec<u8>, [u32; 3]) {
        let mut ifd0 = ifds.ifd0.clone();
        ifd0.push(long(EXIF_IFD_POINTER, exif_at));
        if !ifds.gps.is_empty() {
            ifd0.push(long(GPS_IFD_POINTER, gps_at));
        }
        if let Some(img) = image {
            let [w, h] = img.size_px;
            ifd0.extend([
                long(256, w),                           // ImageWidth
                long(257, h),                           // ImageLength
                shorts(258, &[8, 8, 8]),                // BitsPerSample
                shorts(259, &[1]),                      // Compression: none
                shorts(262, &[2]),                      // PhotometricInterpretation: RGB
                long(273, strip_at),                    // StripOffsets
                shorts(277, &[3]),                      // SamplesPerPixel
                long(278, h),                           // RowsPerStrip
                long(279, count_of(img.samples.len())), // StripByteCounts
                shorts(284, &[1]),                      // PlanarConfiguration: chunky
            ]);
        }
        let mut out = b"II\x2a\x00\x08\x00\x00\x00".to_vec();
        write_ifd(&mut out, &mut ifd0, 0);
        let exif_pos = count_of(out.len());
        write_ifd(&mut out, &mut ifds.exif.clone(), 0);
        let gps_pos = count_of(out.len());
        if !ifds.gps.is_empty() {
            write_ifd(&mut out, &mut ifds.gps.clone(), 0);
        }
        let strip_pos = count_of(out.len());
        (out, [exif_pos, gps_pos, strip_pos])
    };
    // The IFD sizes do not depend on the pointer values: the first pass finds the offsets.
    let (_, [exif_at, gps_at, strip_at]) = build(0, 0, 0);
    let (mut out, _) = build(exif_at, gps_at, strip_at);
    if let Some(img) = image {
        out.extend_from_slice(img.samples);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tiff_file_decodes_to_its_pixels() {
        let samples: Vec<u8> = (0..5 * 3 * 3).map(|i| (i * 5) as u8).collect();
        let ifds = MetadataIfds {
            ifd0: vec![ascii(0x0131, "test")],
            exif: vec![shorts(0xA405, &[50])],
            gps: Vec::new(),
        };
        let bytes = tiff_bytes(
            &ifds,
            Some(RgbStrip {
                size_px: [5, 3],
                samples: &samples,
            }),
        );
        let decoded = image::load_from_memory_with_format(&bytes, image::ImageFormat::Tiff)
            .expect("decodes")
            .to_rgb8();
        assert_eq!(decoded.dimensions(), (5, 3));
        assert_eq!(decoded.as_raw(), &samples);
    }
}
