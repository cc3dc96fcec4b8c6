//! A dense PLY reconstruction streamed into the module piece by piece
//! ([`sfmeval::io::ply_stream`]): the page reads a dropped file a few megabytes at a time
//! (`File.slice`), so the file's bytes never enter WebAssembly memory, which never shrinks.

use js_sys::Uint8Array;
use sfmeval::io::{self, ply_stream::PlyCloudStream};
use sfmeval::pipeline;
use wasm_bindgen::prelude::*;

use crate::{Reconstruction, js_err};

/// A binary PLY point cloud being read piece by piece into a [`Reconstruction`].
#[wasm_bindgen]
pub struct ReconstructionStream {
    name: String,
    file_name: String,
    stream: PlyCloudStream,
}

#[wasm_bindgen]
impl ReconstructionStream {
    /// Starts reading `fileName` (`fileLength` bytes) from its first bytes `head` (64 KiB, or
    /// the whole file if shorter); `name` is shown in the report. `undefined` when the file is
    /// not a binary PLY cloud (read it whole with `new Reconstruction`); throws on a bad
    /// header or more points declared than the file holds.
    pub fn start(
        name: &str,
        #[wasm_bindgen(js_name = fileName)] file_name: &str,
        head: &Uint8Array,
        #[wasm_bindgen(js_name = fileLength)] file_length: f64,
    ) -> Result<Option<ReconstructionStream>, JsError> {
        let context = format!("reconstruction '{name}'");
        let stream = PlyCloudStream::new(&head.to_vec(), file_length as u64)
            .map_err(|e| js_err(&context, e))?;
        Ok(stream.map(|stream| ReconstructionStream {
            name: name.to_string(),
            file_name: file_name.to_string(),
            stream,
        }))
    }

    /// Byte offset of the body: push the file from here on.
    #[wasm_bindgen(getter, js_name = bodyStart)]
    pub fn body_start(&self) -> f64 {
        self.stream.body_start() as f64
    }

    /// Points the header declares.
    #[wasm_bindgen(getter, js_name = declaredPoints)]
    pub fn declared_points(&self) -> f64 {
        self.stream.declared_points() as f64
    }

    /// Points read so far.
    #[wasm_bindgen(getter, js_name = pointsRead)]
    pub fn points_read(&self) -> f64 {
        self.stream.points_read() as f64
    }

    /// Whether every declared point is read (the rest of the file is not needed).
    #[wasm_bindgen(getter, js_name = isComplete)]
    pub fn is_complete(&self) -> bool {
        self.stream.is_complete()
    }

    /// Decodes the next piece of the file (the bytes after the previous piece).
    pub fn push(&mut self, piece: &Uint8Array) {
        // Copied in slices so the module's memory holds at most one slice of the file.
        const SLICE: u32 = 1 << 20;
        let mut buf = vec![0u8; SLICE.min(piece.length()) as usize];
        let mut at = 0;
        while at < piece.length() {
            let end = (at + SLICE).min(piece.length());
            let part = &mut buf[..(end - at) as usize];
            piece.subarray(at, end).copy_to(part);
            self.stream.push(part);
            at = end;
        }
    }

    /// The reconstruction, checked as a whole-file read checks it (a file that ended early is
    /// the same error).
    pub fn finish(self) -> Result<Reconstruction, JsError> {
        let context = format!("reconstruction '{}'", self.name);
        let ply = self.stream.finish().map_err(|e| js_err(&context, e))?;
        let loaded =
            io::point_cloud_from_ply(&self.file_name, ply).map_err(|e| js_err(&context, e))?;
        Ok(Reconstruction {
            input: pipeline::reconstruction_from_cloud(&self.name, loaded),
        })
    }
}
