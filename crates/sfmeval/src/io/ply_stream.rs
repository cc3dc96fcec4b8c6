//! A binary PLY point cloud read in pieces, so a dense cloud never exists twice in memory (once
//! as the file's bytes, once as its positions): the front end reads the file a few megabytes at
//! a time and pushes each piece, and only the decoded positions (and colours) stay.
//!
//! It takes the files a dense-cloud writer produces (COLMAP's `fused.ply`, OpenMVS, Open3D,
//! PDAL, CloudCompare): binary, little or big endian, whose first element is a fixed-stride
//! `vertex` element with no face element anywhere. Anything else (ascii, meshes, list
//! properties in the vertex, the vertex element after another one) is read whole by
//! [`super::ply::read_ply`]; [`PlyCloudStream::new`] says which. The result equals
//! `read_ply` on the whole file, errors included (tests below).

use super::ply::{
    FMT, Header, PlyData, PlyEncoding, VertexRecords, check_data, element_what, empty_data,
    parse_header,
};
use crate::error::{Error, Result};

/// Bytes of the start of a file that [`PlyCloudStream::new`] needs at most: every header it
/// streams ends within them.
pub const HEAD_BYTES: usize = 1 << 16;

/// A binary PLY point cloud being read piece by piece.
pub struct PlyCloudStream {
    data: PlyData,
    records: VertexRecords,
    /// The declared vertex count, as `usize`.
    count: usize,
    declared: u64,
    body_start: usize,
    /// Body bytes pushed so far.
    received: u64,
    /// The start of a record split between two pieces.
    carry: Vec<u8>,
}

impl PlyCloudStream {
    /// Starts reading a file of `file_len` bytes from its first bytes `head` (at least
    /// [`HEAD_BYTES`] of them, or the whole file if shorter). `Ok(None)` when the file is not
    /// one this reader streams (read it whole then); errors are those of `read_ply` on the
    /// same file: a bad header, or more vertices declared than the file can hold.
    pub fn new(head: &[u8], file_len: u64) -> Result<Option<Self>> {
        let header = match parse_header(head) {
            Ok(h) => h,
            // A header longer than the head, or an error read_ply reports itself.
            Err(_) => return Ok(None),
        };
        if header.encoding == PlyEncoding::Ascii || !streamable(&header) {
            return Ok(None);
        }
        let (data, layout) = empty_data(&header)?;
        let vertex = &header.elements[0];
        let Some(stride) = vertex.fixed_stride().filter(|&s| s > 0) else {
            return Ok(None);
        };
        let available = file_len.saturating_sub(header.body_start as u64) / stride as u64;
        if vertex.count > available {
            return Err(Error::CountMismatch {
                format: FMT,
                what: element_what(&vertex.name),
                declared: vertex.count,
                available,
            });
        }
        let big = header.encoding == PlyEncoding::BinaryBigEndian;
        let records = VertexRecords::new(vertex, &layout, stride, big);
        let count = usize::try_from(vertex.count)
            .map_err(|_| Error::unsupported(FMT, "more vertices than this machine can address"))?;
        let mut data = data;
        // Nothing is reserved yet: a caller that refuses the declared count (the page's memory
        // check) has allocated nothing; the first piece reserves it all.
        data.vertices = records.empty_positions(0);
        data.colors = records.has_colors().then(Vec::new);
        Ok(Some(PlyCloudStream {
            data,
            records,
            count,
            declared: vertex.count,
            body_start: header.body_start,
            received: 0,
            carry: Vec::new(),
        }))
    }

    /// Where the body starts: push the file's bytes from this offset on.
    pub fn body_start(&self) -> usize {
        self.body_start
    }

    /// Vertices the header declares.
    pub fn declared_points(&self) -> u64 {
        self.declared
    }

    /// Vertices decoded so far.
    pub fn points_read(&self) -> u64 {
        self.data.vertices.len() as u64
    }

    /// Whether every declared vertex is read (the rest of the file is not needed).
    pub fn is_complete(&self) -> bool {
        self.points_read() == self.declared
    }

    /// Decodes the next piece of the body (the bytes after the previous piece). Bytes after
    /// the last declared vertex are ignored.
    pub fn push(&mut self, piece: &[u8]) {
        let stride = self.records.stride();
        if self.received == 0 && !piece.is_empty() {
            self.data.vertices = self.records.empty_positions(self.count);
            if let Some(colors) = self.data.colors.as_mut() {
                colors.reserve_exact(self.count);
            }
        }
        let wanted = (self.declared * stride as u64).saturating_sub(self.received);
        let mut piece = &piece[..(piece.len() as u64).min(wanted) as usize];
        self.received += piece.len() as u64;
        if !self.carry.is_empty() {
            let need = (stride - self.carry.len()).min(piece.len());
            self.carry.extend_from_slice(&piece[..need]);
            piece = &piece[need..];
            if self.carry.len() < stride {
                return;
            }
            let colors = self.data.colors.as_mut();
            self.records
                .decode(&self.carry, &mut self.data.vertices, colors);
            self.carry.clear();
        }
        let whole = piece.len() - piece.len() % stride;
        let colors = self.data.colors.as_mut();
        self.records
            .decode(&piece[..whole], &mut self.data.vertices, colors);
        self.carry.extend_from_slice(&piece[whole..]);
    }

    /// The cloud, checked as `read_ply` checks it; a file that ended before its last declared
    /// vertex is the same error as from `read_ply`.
    pub fn finish(self) -> Result<PlyData> {
        if !self.is_complete() {
            return Err(Error::CountMismatch {
                format: FMT,
                what: "vertices",
                declared: self.declared,
                available: self.points_read(),
            });
        }
        check_data(self.data)
    }
}

/// Whether the file is a cloud this reader takes: the vertex element first, no face element.
fn streamable(header: &Header) -> bool {
    header.elements.first().is_some_and(|e| e.name == "vertex")
        && !header.elements.iter().any(|e| e.name == "face")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::ply::read_ply;

    /// A binary cloud of `n` points with the properties `props` (type, name), each value
    /// `f(point, property)` written in that type.
    fn cloud(big: bool, n: usize, props: &[(&str, &str)], tail: &str) -> Vec<u8> {
        let fmt = if big {
            "binary_big_endian"
        } else {
            "binary_little_endian"
        };
        let mut head = format!("ply\nformat {fmt} 1.0\ncomment made here\nelement vertex {n}\n");
        for (ty, name) in props {
            head += &format!("property {ty} {name}\n");
        }
        head += tail;
        head += "end_header\n";
        let mut b = head.into_bytes();
        for i in 0..n {
            for (k, (ty, _)) in props.iter().enumerate() {
                let v = ((i * 7919 + k * 104_729) % 1000) as f64 / 7.0 - 50.0;
                macro_rules! put {
                    ($x:expr) => {
                        if big {
                            b.extend($x.to_be_bytes())
                        } else {
                            b.extend($x.to_le_bytes())
                        }
                    };
                }
                match *ty {
                    "float" => put!(v as f32),
                    "double" => put!(v),
                    "uchar" => put!((v.abs() * 5.0) as u8),
                    "ushort" => put!((v.abs() * 900.0) as u16),
                    "int" => put!(v as i32),
                    _ => unreachable!("test type {ty}"),
                }
            }
        }
        b
    }

    /// The file pushed in pieces of the given sizes (cycled), from the body start.
    fn streamed(bytes: &[u8], pieces: &[usize]) -> Result<Option<PlyData>> {
        let head = &bytes[..bytes.len().min(HEAD_BYTES)];
        let Some(mut s) = PlyCloudStream::new(head, bytes.len() as u64)? else {
            return Ok(None);
        };
        let mut pos = s.body_start();
        for &size in pieces.iter().cycle() {
            if pos >= bytes.len() {
                break;
            }
            let end = (pos + size).min(bytes.len());
            s.push(&bytes[pos..end]);
            pos = end;
        }
        s.finish().map(Some)
    }

    const PIECES: [&[usize]; 5] = [&[1], &[7, 3, 1000], &[13], &[1 << 20], &[5, 64, 2, 999]];

    #[test]
    fn equals_reading_the_whole_file_for_any_piece_sizes() {
        let layouts: [&[(&str, &str)]; 4] = [
            &[("float", "x"), ("float", "y"), ("float", "z")],
            &[
                ("float", "x"),
                ("float", "y"),
                ("float", "z"),
                ("float", "nx"),
                ("uchar", "red"),
                ("uchar", "green"),
                ("uchar", "blue"),
                ("uchar", "alpha"),
            ],
            &[("double", "x"), ("double", "y"), ("double", "z")],
            &[
                ("int", "z"),
                ("ushort", "r"),
                ("float", "x"),
                ("ushort", "g"),
                ("double", "y"),
                ("ushort", "b"),
            ],
        ];
        for big in [false, true] {
            for props in layouts {
                for n in [0usize, 1, 2, 1000] {
                    // a trailing element the stream ignores
                    let bytes = cloud(big, n, props, "");
                    let whole = read_ply(&bytes).unwrap();
                    for pieces in PIECES {
                        let got = streamed(&bytes, pieces).unwrap().unwrap();
                        assert_eq!(got, whole, "{props:?} n={n} big={big} {pieces:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn bytes_after_the_vertices_are_ignored() {
        let props = [("float", "x"), ("float", "y"), ("float", "z")];
        let mut bytes = cloud(false, 50, &props, "element extra 2\nproperty uchar q\n");
        bytes.extend([9, 9]);
        let whole = read_ply(&bytes).unwrap();
        for pieces in PIECES {
            assert_eq!(streamed(&bytes, pieces).unwrap().unwrap(), whole);
        }
    }

    #[test]
    fn what_it_does_not_stream_is_left_to_read_ply() {
        let xyz = [("float", "x"), ("float", "y"), ("float", "z")];
        let mesh = cloud(
            false,
            3,
            &xyz,
            "element face 0\nproperty list uchar int vertex_indices\n",
        );
        assert!(streamed(&mesh, &[10]).unwrap().is_none());
        let ascii = b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n";
        assert!(streamed(ascii, &[10]).unwrap().is_none());
        let mut later = b"ply\nformat binary_little_endian 1.0\nelement camera 1\nproperty float f\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n".to_vec();
        later.extend([0u8; 16]);
        assert!(streamed(&later, &[10]).unwrap().is_none());
        // a header not in the head: read whole
        assert!(
            streamed(b"ply\nformat binary_little_endian 1.0\n", &[10])
                .unwrap()
                .is_none()
        );
    }

    #[test]
    fn errors_are_those_of_read_ply() {
        let xyz = [("float", "x"), ("float", "y"), ("float", "z")];
        let full = cloud(false, 100, &xyz, "");
        // truncated in the middle of a record
        let cut = &full[..full.len() - 5];
        let want = read_ply(cut).unwrap_err().to_string();
        assert_eq!(streamed(cut, &[7]).unwrap_err().to_string(), want);
        // a non-finite coordinate
        let mut nan = full.clone();
        let at = nan.len() - 8;
        nan[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
        let want = read_ply(&nan).unwrap_err().to_string();
        assert_eq!(streamed(&nan, &[64]).unwrap_err().to_string(), want);
        // a huge declared count: refused before anything is allocated
        let huge = b"ply\nformat binary_little_endian 1.0\nelement vertex 999999999999\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
        let want = read_ply(huge).unwrap_err().to_string();
        assert_eq!(streamed(huge, &[7]).unwrap_err().to_string(), want);
        // no x: the header error of read_ply
        let noxyz = b"ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float q\nend_header\n\0\0\0\0";
        let want = read_ply(noxyz).unwrap_err().to_string();
        assert_eq!(streamed(noxyz, &[7]).unwrap_err().to_string(), want);
    }

    #[test]
    fn finish_before_the_last_vertex_is_a_count_mismatch() {
        let xyz = [("float", "x"), ("float", "y"), ("float", "z")];
        let bytes = cloud(false, 10, &xyz, "");
        let mut s = PlyCloudStream::new(&bytes, bytes.len() as u64)
            .unwrap()
            .unwrap();
        s.push(&bytes[s.body_start()..s.body_start() + 12 * 4 + 3]);
        assert_eq!(s.points_read(), 4);
        assert!(!s.is_complete());
        let e = s.finish().unwrap_err().to_string();
        assert!(e.contains("10") && e.contains('4'), "{e}");
    }
}
