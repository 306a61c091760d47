//! Source positions: where each entity of an ASCII DXF file starts.
//!
//! Owns a light scan of the raw bytes, independent of the `dxf` crate, that records for
//! every entity record in the BLOCKS and ENTITIES sections its type, handle, layer,
//! paper-space flag and byte/line span. The `dxf` crate keeps no positions, so records are
//! looked up here: model-space entities by handle, entities inside a block by block name,
//! type and rank among the block's entities of that type (the `dxf` crate gives block
//! entities new handles as it reads them, so their handles in memory are not the file's).
//! It must not interpret geometry, and it must never fail: anything it cannot make sense of
//! simply has no record (binary DXF files have none).

use std::collections::HashMap;

use pvt_core::Span;

/// One `0/TYPE` record and the group codes that follow it up to the next `0`.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    /// Entity type as written (`LINE`, `HATCH`, …).
    pub kind: String,
    /// Handle (group 5), 0 when absent or unreadable.
    pub handle: u64,
    /// Layer (group 8), empty when absent.
    pub layer: String,
    /// Group 67 was 1.
    pub paper_space: bool,
    /// Bytes and first line of the record.
    pub span: Span,
    /// True for records in the ENTITIES section, false for BLOCKS.
    pub in_entities: bool,
}

/// Spans of the entity records of an ASCII DXF file.
#[derive(Debug, Default)]
pub struct SourceMap {
    /// Every entity record, in file order.
    pub records: Vec<Record>,
    /// Group-code-10 values (first coordinates: vertices, control and fit points, entity
    /// start points) in the BLOCKS and ENTITIES sections: an upper bound on the points
    /// the drawing's entities hold before blocks are inserted.
    pub points: usize,
    by_handle: HashMap<u64, usize>,
    /// Indices into `records` of each block's entity records, in order, by lower-case name.
    blocks: HashMap<String, Vec<usize>>,
}

/// True when the bytes look like ASCII DXF (not binary DXF or DXB).
pub fn is_ascii_dxf(bytes: &[u8]) -> bool {
    !(bytes.starts_with(b"AutoCAD Binary DXF") || bytes.starts_with(b"AutoCAD DXB"))
}

impl SourceMap {
    /// Scans the bytes; binary files and anything unreadable give an empty map.
    pub fn scan(bytes: &[u8]) -> SourceMap {
        let mut map = SourceMap::default();
        if !is_ascii_dxf(bytes) {
            return map;
        }
        let mut lines = pvt_core::text::lines(bytes);
        let mut section = String::new();
        let mut expect_section_name = false;
        let mut open: Option<Record> = None;
        // The block whose entities are being scanned, and whether its name is still to come.
        let mut block: Option<String> = None;
        let mut block_header = false;
        while let (Some(code_line), Some(value_line)) = (lines.next(), lines.next()) {
            let offset = code_line.range.start;
            let value = String::from_utf8_lossy(trim_cr(&bytes[value_line.range]));
            let value = value.trim();
            let code: Option<i32> = std::str::from_utf8(trim_cr(&bytes[code_line.range.clone()]))
                .ok()
                .and_then(|s| s.trim().parse().ok());
            let Some(code) = code else { continue };
            if code == 10 && (section == "ENTITIES" || section == "BLOCKS") {
                map.points += 1;
            }
            if code == 0 {
                if let Some(mut r) = open.take() {
                    r.span.end = offset;
                    map.push(r, block.as_deref());
                }
                block_header = false;
                match value {
                    "SECTION" => expect_section_name = true,
                    "ENDSEC" => {
                        section.clear();
                        block = None;
                    }
                    "BLOCK" if section == "BLOCKS" => {
                        block = None;
                        block_header = true;
                    }
                    "ENDBLK" => block = None,
                    "BLOCK" | "EOF" => {}
                    kind if section == "ENTITIES" || section == "BLOCKS" => {
                        open = Some(Record {
                            kind: kind.to_string(),
                            handle: 0,
                            layer: String::new(),
                            paper_space: false,
                            span: Span {
                                start: offset,
                                end: offset,
                                line: u32::try_from(code_line.number).unwrap_or(u32::MAX),
                            },
                            in_entities: section == "ENTITIES",
                        });
                    }
                    _ => {}
                }
                continue;
            }
            if code == 2 && expect_section_name {
                section = value.to_string();
                expect_section_name = false;
                continue;
            }
            if code == 2 && block_header {
                block = Some(value.to_lowercase());
                block_header = false;
                continue;
            }
            if let Some(r) = open.as_mut() {
                match code {
                    5 => r.handle = u64::from_str_radix(value, 16).unwrap_or(0),
                    8 => r.layer = value.to_string(),
                    67 => r.paper_space = value == "1",
                    _ => {}
                }
            }
        }
        if let Some(mut r) = open.take() {
            r.span.end = bytes.len();
            map.push(r, block.as_deref());
        }
        map
    }

    fn push(&mut self, r: Record, block: Option<&str>) {
        let index = self.records.len();
        if let (Some(name), false) = (block, r.in_entities) {
            self.blocks.entry(name.to_string()).or_default().push(index);
        } else if r.handle != 0 {
            self.by_handle.entry(r.handle).or_insert(index);
        }
        self.records.push(r);
    }

    /// The index of the model-space record with this handle and type, if the scan found one.
    pub fn find(&self, handle: u64, kind: &str) -> Option<usize> {
        let i = *self.by_handle.get(&handle)?;
        same_kind(&self.records[i].kind, kind).then_some(i)
    }

    /// The index of the `rank`-th (from 0) record of type `kind` in block `block`
    /// (compared case-insensitively), if the scan found one.
    pub fn in_block(&self, block: &str, kind: &str, rank: usize) -> Option<usize> {
        self.blocks
            .get(&block.to_lowercase())?
            .iter()
            .copied()
            .filter(|&i| same_kind(&self.records[i].kind, kind))
            .nth(rank)
    }

    /// The span of the record with this handle and type, if the scan found one.
    pub fn span(&self, handle: u64, kind: &str) -> Option<Span> {
        self.find(handle, kind).map(|i| self.records[i].span)
    }
}

/// True when a record written as `written` is an entity the `dxf` crate calls `kind`.
fn same_kind(written: &str, kind: &str) -> bool {
    written == kind || (kind == "LINE" && written == "3DLINE")
}

impl SourceMap {
    /// Spans of the records of type `kind` that directly follow record `index` (the VERTEX
    /// records of a POLYLINE, whose handles the `dxf` crate does not keep).
    pub fn following(&self, index: usize, kind: &str) -> Vec<Span> {
        let Some(rest) = self.records.get(index + 1..) else {
            return Vec::new();
        };
        rest.iter()
            .take_while(|r| r.kind == kind)
            .map(|r| r.span)
            .collect()
    }
}

/// A line's bytes without the `\r` before its `\n`.
fn trim_cr(line: &[u8]) -> &[u8] {
    line.strip_suffix(b"\r").unwrap_or(line)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_entity_lines_and_handles() {
        let text = "0\r\nSECTION\r\n2\r\nENTITIES\r\n0\r\nLINE\r\n5\r\n1F\r\n8\r\nCUT\r\n10\r\n0\r\n0\r\nTEXT\r\n67\r\n1\r\n0\r\nENDSEC\r\n0\r\nEOF\r\n";
        let map = SourceMap::scan(text.as_bytes());
        assert_eq!(map.records.len(), 2);
        let line = map.span(0x1F, "LINE").unwrap();
        assert_eq!(line.line, 5);
        assert_eq!(&text[line.start..line.start + 1], "0");
        assert_eq!(&text[line.end..line.end + 6], "0\r\nTEX");
        assert_eq!(map.records[0].layer, "CUT");
        assert!(map.records[1].paper_space);
        assert_eq!(map.span(0x1F, "ARC"), None);
        assert!(SourceMap::scan(b"AutoCAD Binary DXF\r\n\x1a\x00")
            .records
            .is_empty());
        assert!(SourceMap::scan(b"\xff\xfe\n0\n").records.is_empty());
    }
}
