//! A minimal ZIP writer (what an FMU is): files deflated, names in UTF-8,
//! a fixed date (1980-01-01) so that the same content gives the same
//! archive; no ZIP64 (an FMU of cdyn is a few megabytes).

use std::io::Write;

/// An archive being written into memory.
#[derive(Default)]
pub(super) struct Zip {
    bytes: Vec<u8>,
    central: Vec<u8>,
    entries: u16,
}

fn u16le(out: &mut Vec<u8>, x: u16) {
    out.extend_from_slice(&x.to_le_bytes());
}

fn u32le(out: &mut Vec<u8>, x: u32) {
    out.extend_from_slice(&x.to_le_bytes());
}

/// 1980-01-01 00:00 in MS-DOS's date encoding.
const DOS_DATE: u16 = (1 << 5) | 1;

impl Zip {
    /// Adds the file `name` with `content`, deflated.
    pub(super) fn add(&mut self, name: &str, content: &[u8]) -> std::io::Result<()> {
        let mut deflater = flate2::write::DeflateEncoder::new(Vec::new(), flate2::Compression::default());
        deflater.write_all(content)?;
        let packed = deflater.finish()?;
        let crc = crc32fast::hash(content);
        let too_large = || std::io::Error::other(format!("{name}: larger than a ZIP without ZIP64 holds"));
        let (csize, usize_) = (
            u32::try_from(packed.len()).map_err(|_| too_large())?,
            u32::try_from(content.len()).map_err(|_| too_large())?,
        );
        let offset = u32::try_from(self.bytes.len()).map_err(|_| too_large())?;
        let header = |out: &mut Vec<u8>| {
            u16le(out, 20); // version needed: 2.0 (deflate)
            u16le(out, 0x0800); // names in UTF-8
            u16le(out, 8); // deflate
            u16le(out, 0); // time
            u16le(out, DOS_DATE);
            u32le(out, crc);
            u32le(out, csize);
            u32le(out, usize_);
            u16le(out, name.len() as u16);
            u16le(out, 0); // extra field
        };
        u32le(&mut self.bytes, 0x0403_4b50);
        header(&mut self.bytes);
        self.bytes.extend_from_slice(name.as_bytes());
        self.bytes.extend_from_slice(&packed);
        u32le(&mut self.central, 0x0201_4b50);
        u16le(&mut self.central, (3 << 8) | 20); // made by: Unix, 2.0
        header(&mut self.central);
        u16le(&mut self.central, 0); // comment
        u16le(&mut self.central, 0); // disk
        u16le(&mut self.central, 0); // internal attributes
        u32le(&mut self.central, 0o100644 << 16); // a regular file, rw-r--r--
        u32le(&mut self.central, offset);
        self.central.extend_from_slice(name.as_bytes());
        self.entries += 1;
        Ok(())
    }

    /// The archive's bytes.
    pub(super) fn finish(mut self) -> Vec<u8> {
        let (start, size) = (self.bytes.len() as u32, self.central.len() as u32);
        self.bytes.append(&mut self.central);
        u32le(&mut self.bytes, 0x0605_4b50);
        u16le(&mut self.bytes, 0);
        u16le(&mut self.bytes, 0);
        u16le(&mut self.bytes, self.entries);
        u16le(&mut self.bytes, self.entries);
        u32le(&mut self.bytes, size);
        u32le(&mut self.bytes, start);
        u16le(&mut self.bytes, 0);
        self.bytes
    }
}
