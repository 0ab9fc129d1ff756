//! Reading `.npy` files safely: every size checked before anything is allocated.
//!
//! The format (numpy's `numpy.lib.format`): the magic `\x93NUMPY`, a version byte pair, the
//! header's length (2 bytes little-endian in version 1, 4 in versions 2 and 3), then the
//! header, a Python dict literal such as
//! `{'descr': '<f4', 'fortran_order': False, 'shape': (5, 5, 16, 16, 13), }`, then the body.
//!
//! Why not npyz's reader (npyz still writes our files): its header goes through a general
//! Python-literal grammar that backtracks exponentially on nested brackets (a 200-byte file
//! with 20 nested `{` ran for hours), and it multiplies the shape without checking for
//! overflow. The header of an array file is a fixed, tiny grammar: this module reads it in
//! one pass with no recursion, after bounding its length as numpy itself does
//! ([`MAX_HEADER`], numpy's `max_header_size`), and it checks the body's size against the
//! file's before it allocates. The bytes a file can hold bound every allocation.
//!
//! numpy's defaults that slf does not store are converted, each with a [`Npy::notes`] line
//! for the caller to show: float64 to float32, Fortran order to C order, big-endian to
//! native.

use std::fmt;
use std::fs::File;
use std::io::{BufReader, Read};
use std::path::Path;

/// The longest header read, in bytes (numpy's own default `max_header_size`).
pub const MAX_HEADER: usize = 10_000;

/// The most axes an array may have (numpy's `NPY_MAXDIMS` is 64).
pub const MAX_AXES: usize = 64;

const MAGIC: &[u8; 6] = b"\x93NUMPY";

/// An element type slf reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Element {
    F32,
    F64,
    U16,
}

impl Element {
    /// Bytes a value.
    pub fn size(self) -> u64 {
        match self {
            Element::F32 => 4,
            Element::F64 => 8,
            Element::U16 => 2,
        }
    }
}

/// An array's values as slf keeps them: float32 (float64 converted) or uint16.
#[derive(Clone, Debug, PartialEq)]
pub enum Values {
    F32(Vec<f32>),
    U16(Vec<u16>),
}

impl Values {
    /// As f32: uint16 as a fraction of 65535 (slf's convention for light fields and cubes).
    pub fn into_f32(self) -> Vec<f32> {
        match self {
            Values::F32(v) => v,
            Values::U16(v) => v.into_iter().map(|x| f32::from(x) / 65535.0).collect(),
        }
    }
}

/// A `.npy` array in C order.
#[derive(Clone, Debug, PartialEq)]
pub struct Npy {
    /// The shape, slowest axis first.
    pub shape: Vec<usize>,
    pub values: Values,
    /// Conversions made on the way in (float64, Fortran order, big-endian), one line each.
    pub notes: Vec<String>,
}

/// What is wrong with a `.npy` file, and where. `Display` is one line naming the file.
#[derive(Debug)]
pub struct NpyError {
    /// The file.
    pub path: String,
    /// What is wrong.
    pub kind: NpyErrorKind,
}

/// The ways a `.npy` file can be wrong.
#[derive(Debug)]
pub enum NpyErrorKind {
    Io(std::io::Error),
    /// A FIFO, device or folder: not read (it could block forever or never end).
    NotAFile,
    /// The first six bytes are not `\x93NUMPY`.
    Magic,
    /// A format version other than 1.0, 2.0, 3.0.
    Version(u8, u8),
    /// The header is longer than [`MAX_HEADER`] bytes.
    HeaderTooLong(u64),
    /// The header runs past the end of the file.
    HeaderPastEnd {
        header: u64,
        file: u64,
    },
    /// The header does not parse: at byte `at` of the header, `what`.
    Header {
        at: usize,
        what: String,
    },
    /// A dtype this reader does not take.
    Dtype(String),
    /// The values' byte count does not fit in 64 bits.
    Overflow {
        shape: Vec<u64>,
    },
    /// The file holds fewer bytes than the shape needs.
    Truncated {
        expected: u64,
        found: u64,
    },
    /// The file holds bytes after the values its header states.
    Trailing {
        expected: u64,
        extra: u64,
    },
    /// The values would not fit the memory cap ([`crate::io::budget`]) or the allocator.
    Memory(String),
    /// The array's shape is not what the caller needs.
    Shape(String),
    /// A finite float64 value (the `index`-th in the file's order) beyond float32's range.
    Range {
        index: u64,
        value: f64,
    },
}

impl fmt::Display for NpyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: ", self.path)?;
        match &self.kind {
            NpyErrorKind::Io(e) => write!(f, "{e}"),
            NpyErrorKind::NotAFile => write!(f, "not a regular file"),
            NpyErrorKind::Magic => write!(f, "not an .npy file (the magic \\x93NUMPY is missing)"),
            NpyErrorKind::Version(a, b) => write!(f, ".npy format version {a}.{b}, expected 1.0, 2.0 or 3.0"),
            NpyErrorKind::HeaderTooLong(n) => {
                write!(f, "header of {n} bytes, longer than numpy's limit of {MAX_HEADER}")
            }
            NpyErrorKind::HeaderPastEnd { header, file } => {
                write!(f, "header of {header} bytes runs past the end of the {file}-byte file")
            }
            NpyErrorKind::Header { at, what } => write!(f, "header, byte {at}: {what}"),
            NpyErrorKind::Dtype(d) => {
                write!(f, "dtype {d}, expected float32 ('<f4'), float64 ('<f8') or uint16 ('<u2')")
            }
            NpyErrorKind::Overflow { shape } => write!(f, "shape {shape:?} has more values than 64 bits can count"),
            NpyErrorKind::Truncated { expected, found } => {
                write!(f, "truncated body: header promises {expected} values, file holds {found}")
            }
            NpyErrorKind::Trailing { expected, extra } => write!(
                f,
                "{extra} bytes after the {expected} values the header states (the header does not describe the file)"
            ),
            NpyErrorKind::Memory(what) => write!(f, "{what}"),
            NpyErrorKind::Shape(what) => write!(f, "{what}"),
            NpyErrorKind::Range { index, value } => write!(
                f,
                "value {index} (in the file's order) is {value:e}, beyond float32's range (+-3.4e38) that slf \
                 computes in"
            ),
        }
    }
}

impl std::error::Error for NpyError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match &self.kind {
            NpyErrorKind::Io(e) => Some(e),
            _ => None,
        }
    }
}

impl NpyError {
    /// An error about `path`.
    pub fn new(path: &Path, kind: NpyErrorKind) -> Self {
        Self { path: path.display().to_string(), kind }
    }
}

/// Reads a `.npy` file of float32, float64 or uint16 values.
///
/// # Errors
/// [`NpyError`]: the file, and what is wrong in it and where.
pub fn read(path: &Path) -> Result<Npy, NpyError> {
    read_checked(path, |_, _| Ok(()))
}

/// As [`read`], with `check` called on the header's shape and element type before the body
/// is read or anything is allocated for it: a caller that knows the shape it needs (a
/// frame of the capture's size, a light field within the size cap) refuses a file that
/// claims another, whatever the file's length (a sparse file can claim gigabytes).
///
/// # Errors
/// [`NpyError`]: the file, and what is wrong in it and where; `check`'s message as
/// [`NpyErrorKind::Shape`].
pub fn read_checked(path: &Path, check: impl FnOnce(&[usize], Element) -> Result<(), String>) -> Result<Npy, NpyError> {
    let err = |kind| NpyError::new(path, kind);
    // Look before opening: opening a FIFO blocks until a writer comes.
    let meta = std::fs::metadata(path).map_err(|e| err(NpyErrorKind::Io(e)))?;
    if !meta.is_file() {
        return Err(err(NpyErrorKind::NotAFile));
    }
    let file = File::open(path).map_err(|e| err(NpyErrorKind::Io(e)))?;
    read_from_checked(BufReader::new(file), meta.len(), check).map_err(err)
}

/// Reads an array from `r`, which holds `len` bytes in all.
///
/// # Errors
/// What is wrong, without the file's name.
pub fn read_from(r: impl Read, len: u64) -> Result<Npy, NpyErrorKind> {
    read_from_checked(r, len, |_, _| Ok(()))
}

/// Where an array's values lie in its file and how they are stored: what the header says,
/// checked against the file's length (the body is exactly the values: no fewer, no more).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Layout {
    /// The shape, slowest axis first.
    pub shape: Vec<usize>,
    pub element: Element,
    /// Big-endian values (swapped to native as they are read).
    pub swap: bool,
    /// Stored first axis fastest (Fortran order).
    pub fortran_order: bool,
    /// The body's first byte in the file.
    pub body: u64,
    /// Values in the body.
    pub count: u64,
    /// The header's type string (`'<u2'`), for notes.
    pub descr: String,
}

/// Reads the header of the array `r` holds (`len` bytes in all), calls `check` on its
/// shape and element type, and checks the body's length; nothing is allocated for the body.
///
/// # Errors
/// What is wrong, without the file's name.
pub fn read_layout(
    r: &mut impl Read,
    len: u64,
    check: impl FnOnce(&[usize], Element) -> Result<(), String>,
) -> Result<Layout, NpyErrorKind> {
    let io = NpyErrorKind::Io;
    let mut preamble = [0u8; 8];
    if len < 10 {
        return Err(NpyErrorKind::Magic);
    }
    r.read_exact(&mut preamble).map_err(io)?;
    if &preamble[..6] != MAGIC {
        return Err(NpyErrorKind::Magic);
    }
    let (major, minor) = (preamble[6], preamble[7]);
    let (header_len, start) = match (major, minor) {
        (1, 0) => {
            let mut b = [0u8; 2];
            r.read_exact(&mut b).map_err(io)?;
            (u64::from(u16::from_le_bytes(b)), 10)
        }
        (2, 0) | (3, 0) => {
            let mut b = [0u8; 4];
            r.read_exact(&mut b).map_err(io)?;
            (u64::from(u32::from_le_bytes(b)), 12)
        }
        _ => return Err(NpyErrorKind::Version(major, minor)),
    };
    if header_len > MAX_HEADER as u64 {
        return Err(NpyErrorKind::HeaderTooLong(header_len));
    }
    if start + header_len > len {
        return Err(NpyErrorKind::HeaderPastEnd { header: header_len, file: len });
    }
    let mut text = vec![0u8; header_len as usize];
    r.read_exact(&mut text).map_err(io)?;
    let header = Header::parse(&text)?;
    let (element, swap) = header.element()?;
    let mut shape64 = Vec::with_capacity(header.shape.len());
    shape64.extend_from_slice(&header.shape);
    let count = header.shape.iter().try_fold(1u64, |n, &d| n.checked_mul(d));
    let bytes = count.and_then(|n| n.checked_mul(element.size()));
    let (Some(count), Some(bytes)) = (count, bytes) else {
        return Err(NpyErrorKind::Overflow { shape: shape64 });
    };
    let body = len - start - header_len;
    if bytes > body {
        return Err(NpyErrorKind::Truncated { expected: count, found: body / element.size() });
    }
    // numpy writes nothing after the values: bytes past them mean a header that states a
    // smaller shape than the writer wrote (a lying or hand-edited header), so the file is
    // refused, not read in part.
    if bytes < body {
        return Err(NpyErrorKind::Trailing { expected: count, extra: body - bytes });
    }
    let shape = header
        .shape
        .iter()
        .map(|&d| usize::try_from(d))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|_| NpyErrorKind::Overflow { shape: shape64.clone() })?;
    check(&shape, element).map_err(NpyErrorKind::Shape)?;
    usize::try_from(count).map_err(|_| NpyErrorKind::Overflow { shape: shape64 })?;
    Ok(Layout {
        shape,
        element,
        swap,
        fortran_order: header.fortran_order,
        body: start + header_len,
        count,
        descr: header.descr,
    })
}

/// As [`read_from`], with `check` on the shape and element type before the body is read.
///
/// # Errors
/// What is wrong, without the file's name.
pub fn read_from_checked(
    mut r: impl Read,
    len: u64,
    check: impl FnOnce(&[usize], Element) -> Result<(), String>,
) -> Result<Npy, NpyErrorKind> {
    let Layout { shape, element, swap, fortran_order, count, descr, .. } = read_layout(&mut r, len, check)?;
    let bytes = count * element.size();
    // What the read holds at its peak: the values as kept (f32, or u16) and, for a Fortran-
    // order array, their copy in C order; the body is read a chunk at a time.
    let kept = if element == Element::U16 { 2 } else { 4 };
    let need = count.saturating_mul(kept).saturating_mul(if fortran_order { 2 } else { 1 });
    crate::io::budget::check(need, &format!("reading {count} values"), "a smaller array")
        .map_err(|e| NpyErrorKind::Memory(e.to_string()))?;
    // Checked in `read_layout`.
    let count_usize = usize::try_from(count).unwrap_or(usize::MAX);

    let mut notes = Vec::new();
    if swap {
        notes.push(format!("big-endian {descr} converted to little-endian"));
    }
    let mut chunk = vec![0u8; CHUNK];
    let values =
        match element {
            Element::F32 => {
                let mut v = reserve::<f32>(count_usize)?;
                read_chunks(&mut r, bytes, &mut chunk, 4, |c| {
                    v.extend(c.chunks_exact(4).map(|w| f32::from_bits(word32(w, swap))))
                })?;
                Values::F32(v)
            }
            Element::F64 => {
                notes.push("float64 converted to float32".into());
                let mut v = reserve::<f32>(count_usize)?;
                // A finite float64 beyond float32's range would become infinite: say so, not
                // "not finite" of a value the file holds as finite.
                let mut beyond = None;
                read_chunks(&mut r, bytes, &mut chunk, 8, |c| {
                    for w in c.chunks_exact(8) {
                        let mut b = [0u8; 8];
                        b.copy_from_slice(w);
                        let x = f64::from_bits(if swap { u64::from_be_bytes(b) } else { u64::from_le_bytes(b) });
                        if beyond.is_none() && x.is_finite() && x.abs() > f64::from(f32::MAX) {
                            beyond = Some((v.len() as u64, x));
                        }
                        v.push(x as f32);
                    }
                })?;
                if let Some((index, value)) = beyond {
                    return Err(NpyErrorKind::Range { index, value });
                }
                Values::F32(v)
            }
            Element::U16 => {
                let mut v = reserve::<u16>(count_usize)?;
                read_chunks(&mut r, bytes, &mut chunk, 2, |c| {
                    v.extend(c.chunks_exact(2).map(|w| {
                        if swap { u16::from_be_bytes([w[0], w[1]]) } else { u16::from_le_bytes([w[0], w[1]]) }
                    }))
                })?;
                Values::U16(v)
            }
        };
    let values = if fortran_order && shape.len() > 1 {
        notes.push("Fortran-order array converted to C order".into());
        match values {
            Values::F32(v) => Values::F32(fortran_to_c(&v, &shape)),
            Values::U16(v) => Values::U16(fortran_to_c(&v, &shape)),
        }
    } else {
        values
    };
    Ok(Npy { shape, values, notes })
}

/// The body is read this many bytes at a time (a multiple of every element's size).
const CHUNK: usize = 1 << 20;

/// An empty vector with room for `n` values, or the memory error (not an abort).
fn reserve<T>(n: usize) -> Result<Vec<T>, NpyErrorKind> {
    let mut v = Vec::new();
    v.try_reserve_exact(n).map_err(|_| {
        NpyErrorKind::Memory(format!(
            "reading {n} values: the allocator refused {} (ulimit -v, or the machine's memory)",
            crate::io::budget::gib((n * std::mem::size_of::<T>()) as u64)
        ))
    })?;
    Ok(v)
}

/// Reads `bytes` bytes of `r` through `chunk`, handing each read part (whole elements of
/// `size` bytes) to `take`.
fn read_chunks(
    r: &mut impl Read,
    bytes: u64,
    chunk: &mut [u8],
    size: usize,
    mut take: impl FnMut(&[u8]),
) -> Result<(), NpyErrorKind> {
    let mut left = bytes;
    while left > 0 {
        let n = chunk.len().min(usize::try_from(left).unwrap_or(usize::MAX));
        let n = n - n % size;
        let part = &mut chunk[..n];
        r.read_exact(part).map_err(NpyErrorKind::Io)?;
        take(part);
        left -= n as u64;
    }
    Ok(())
}

fn word32(c: &[u8], swap: bool) -> u32 {
    let b = [c[0], c[1], c[2], c[3]];
    if swap { u32::from_be_bytes(b) } else { u32::from_le_bytes(b) }
}

/// `data` in Fortran order (first axis fastest) of `shape`, in C order (last axis fastest).
fn fortran_to_c<T: Copy>(data: &[T], shape: &[usize]) -> Vec<T> {
    // Fortran strides: axis a steps by the product of the axes before it.
    let mut strides = vec![1usize; shape.len()];
    for a in 1..shape.len() {
        strides[a] = strides[a - 1] * shape[a - 1];
    }
    let mut index = vec![0usize; shape.len()];
    let mut out = Vec::with_capacity(data.len());
    let mut at = 0usize;
    for _ in 0..data.len() {
        out.push(data[at]);
        // Advance the C-order multi-index (last axis fastest), keeping the Fortran offset.
        for a in (0..shape.len()).rev() {
            index[a] += 1;
            at += strides[a];
            if index[a] < shape[a] {
                break;
            }
            at -= strides[a] * shape[a];
            index[a] = 0;
        }
    }
    out
}

/// The three keys of an array header.
#[derive(Debug)]
struct Header {
    descr: String,
    fortran_order: bool,
    shape: Vec<u64>,
}

impl Header {
    /// Parses `{'descr': STR, 'fortran_order': BOOL, 'shape': (INT, ...), }` in one pass.
    fn parse(text: &[u8]) -> Result<Self, NpyErrorKind> {
        let mut p = Parser { text, at: 0 };
        let (mut descr, mut fortran, mut shape) = (None, None, None);
        p.skip_space();
        p.expect(b'{')?;
        loop {
            p.skip_space();
            if p.eat(b'}') {
                break;
            }
            let key_at = p.at;
            let key = p.string()?;
            p.skip_space();
            p.expect(b':')?;
            p.skip_space();
            let slot_taken = match key.as_str() {
                "descr" => {
                    if p.peek() == Some(b'[') {
                        return Err(p.error("structured dtypes are not supported; save a plain array"));
                    }
                    descr.replace(p.string()?).is_some()
                }
                "fortran_order" => fortran.replace(p.boolean()?).is_some(),
                "shape" => shape.replace(p.tuple()?).is_some(),
                other => return Err(Parser { text, at: key_at }.error(&format!("unexpected key {other:?}"))),
            };
            if slot_taken {
                return Err(Parser { text, at: key_at }.error(&format!("key {key:?} given twice")));
            }
            p.skip_space();
            if p.eat(b',') {
                continue;
            }
            p.expect(b'}')?;
            break;
        }
        p.skip_space();
        if p.at != text.len() {
            return Err(p.error("text after the header's closing brace"));
        }
        let missing = |k: &str| Parser { text, at: text.len() }.error(&format!("key {k:?} is missing"));
        Ok(Self {
            descr: descr.ok_or_else(|| missing("descr"))?,
            fortran_order: fortran.ok_or_else(|| missing("fortran_order"))?,
            shape: shape.ok_or_else(|| missing("shape"))?,
        })
    }

    /// The element type and whether its bytes need swapping (big-endian).
    fn element(&self) -> Result<(Element, bool), NpyErrorKind> {
        let d = self.descr.as_bytes();
        let bad = || NpyErrorKind::Dtype(format!("'{}'", self.descr));
        let (&order, kind) = d.split_first().ok_or_else(bad)?;
        let swap = match order {
            b'<' | b'=' | b'|' => false,
            b'>' => true,
            _ => return Err(bad()),
        };
        let e = match kind {
            b"f4" => Element::F32,
            b"f8" => Element::F64,
            b"u2" => Element::U16,
            _ => return Err(bad()),
        };
        Ok((e, swap))
    }
}

/// A cursor over header bytes. Every method moves forward or fails: the parse is linear.
struct Parser<'a> {
    text: &'a [u8],
    at: usize,
}

impl Parser<'_> {
    fn error(&self, what: &str) -> NpyErrorKind {
        NpyErrorKind::Header { at: self.at, what: what.into() }
    }

    fn peek(&self) -> Option<u8> {
        self.text.get(self.at).copied()
    }

    fn eat(&mut self, c: u8) -> bool {
        let hit = self.peek() == Some(c);
        self.at += usize::from(hit);
        hit
    }

    fn expect(&mut self, c: u8) -> Result<(), NpyErrorKind> {
        if self.eat(c) {
            return Ok(());
        }
        Err(match self.peek() {
            Some(x) if x.is_ascii_graphic() => self.error(&format!("expected '{}', found '{}'", c as char, x as char)),
            Some(x) => self.error(&format!("expected '{}', found byte 0x{x:02x}", c as char)),
            None => self.error(&format!("expected '{}', found the end", c as char)),
        })
    }

    fn skip_space(&mut self) {
        while matches!(self.peek(), Some(b' ' | b'\t' | b'\n' | b'\r')) {
            self.at += 1;
        }
    }

    /// A quoted string without escapes (keys and dtypes never need them).
    fn string(&mut self) -> Result<String, NpyErrorKind> {
        let quote = match self.peek() {
            Some(q @ (b'\'' | b'"')) => q,
            _ => return Err(self.error("expected a quoted string")),
        };
        self.at += 1;
        let start = self.at;
        while let Some(c) = self.peek() {
            if c == quote {
                let s = &self.text[start..self.at];
                self.at += 1;
                return Ok(String::from_utf8_lossy(s).into_owned());
            }
            if c == b'\\' || !(c.is_ascii_graphic() || c == b' ') || self.at - start > 64 {
                return Err(self.error("unexpected character in a string"));
            }
            self.at += 1;
        }
        Err(self.error("unterminated string"))
    }

    fn boolean(&mut self) -> Result<bool, NpyErrorKind> {
        for (word, value) in [(&b"True"[..], true), (b"False", false)] {
            if self.text[self.at..].starts_with(word) {
                self.at += word.len();
                return Ok(value);
            }
        }
        Err(self.error("expected True or False"))
    }

    /// `()`, `(n,)`, `(n, m, ...)` of non-negative integers (a Python 2 `L` suffix allowed).
    fn tuple(&mut self) -> Result<Vec<u64>, NpyErrorKind> {
        self.expect(b'(')?;
        let mut out = Vec::new();
        loop {
            self.skip_space();
            if self.eat(b')') {
                return Ok(out);
            }
            if out.len() == MAX_AXES {
                return Err(self.error(&format!("more than {MAX_AXES} axes")));
            }
            out.push(self.integer()?);
            self.skip_space();
            if self.eat(b',') {
                continue;
            }
            self.expect(b')')?;
            return Ok(out);
        }
    }

    fn integer(&mut self) -> Result<u64, NpyErrorKind> {
        let start = self.at;
        let mut n: u64 = 0;
        while let Some(c @ b'0'..=b'9') = self.peek() {
            n = n
                .checked_mul(10)
                .and_then(|n| n.checked_add(u64::from(c - b'0')))
                .ok_or_else(|| self.error("an axis length does not fit in 64 bits"))?;
            self.at += 1;
        }
        if self.at == start {
            return Err(self.error("expected an axis length"));
        }
        self.eat(b'L');
        Ok(n)
    }
}
