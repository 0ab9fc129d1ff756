//! The dictionary blob: how dictionaries sit in flash.
//!
//! One format serves a single [`Dictionary`] and an [`Ensemble`] of K members. All
//! integers and floats are little-endian:
//!
//! | offset | size | field |
//! | --- | --- | --- |
//! | 0 | 4 | magic `b"SLFD"` |
//! | 4 | 2 | format version: 1, or [`BLOB_VERSION`] (= 2) with trained schedules |
//! | 6 | 2 | reserved, 0 |
//! | 8 | 10 | patch dimensions `PS, PT, PU, PV, B` (u16 each) |
//! | 18 | 2 | member count K (u16, >= 1) |
//! | 20 | 4 | payload length in bytes (u32): the members' `K * 4 * (PS^2 + PT^2 + PU^2 + PV^2 + B^2)`, plus the schedules' in version 2 |
//! | 24 | members | per member, `D_1 .. D_5` (synthesis matrices, columns are atoms), each row-major f32 |
//! | | schedules | version 2 only: the cold, the warm, then the alone [`Schedule`] ([`Schedules`]), each `T` (u16), its cold start (u16: 0 minimum-norm, 1 band-gain fill), `T` sigmas, `T` mus, then the `PS + PT + PU + PV + B` group weights (f32) |
//! | 24 + payload | 4 | CRC-32/ISO-HDLC (zlib's, PNG's) of every byte before it |
//!
//! [`Ensemble::new`] checks, in this order: length, magic, version, reserved, dimensions,
//! member count, payload length, checksum, then every matrix for non-finite values and
//! orthonormality, then (version 2) each schedule's length and ranges ([`Schedule::new`]).
//! Each failure is its own [`DictionaryError`] variant. After that, [`Ensemble::member`]
//! only copies one member's 1 KiB out of flash. A version 1 blob is read as before: its
//! solves take the hand-set schedule.

use core::marker::PhantomData;

use crc::{CRC_32_ISO_HDLC, Crc};

use crate::operators::dictionary::{Dictionary, DictionaryError, Factors};
use crate::operators::mode::{Mode, ModeMatrix};
use crate::operators::schedule::{MAX_STEPS, Schedule, Schedules, Weights};
use crate::operators::shape::Shape;
use crate::sensor::extent::Array;

/// The shipped default ensemble for the paper's patch (5 x 5 x 4 x 4 x 13): 8 members
/// trained by `cargo run --release -p slf-host -- train -o firmware/dictionaries/ensemble8.slfd`
/// (all defaults: 48 realistic training scenes of 60 x 60 lenslets, white-balanced as the
/// decoder balances a capture, 20,000 patches, tau 100, 10 iterations, seed 1; member 0 is
/// the fixed 5D DCT) on rendered scenes only, never the named test scenes or real data.
/// `Ensemble::<PaperShape>::new(DEFAULT_ENSEMBLE)` validates it.
pub static DEFAULT_ENSEMBLE: &[u8] = include_bytes!("../../dictionaries/ensemble8.slfd");

/// The shipped default ensemble for the full-view patch (5 x 5 x 5 x 5 x 13), with its
/// trained schedules (format version 2): 8 members trained by `cargo run --release -p
/// slf-host -- train --patch-views 5 -o fullview8-ensemble.slfd` (the same defaults and
/// training scenes as [`DEFAULT_ENSEMBLE`]), then its schedules by `slf train-schedule
/// fullview8-ensemble.slfd -o firmware/dictionaries/fullview8.slfd` (all defaults: a cold
/// schedule of 24 steps and a warm one of 16, on 1,024 patches of 24 realistic training
/// scenes). `Ensemble::<FullViewShape>::new(DEFAULT_FULL_VIEW_ENSEMBLE)` validates it.
pub static DEFAULT_FULL_VIEW_ENSEMBLE: &[u8] = include_bytes!("../../dictionaries/fullview8.slfd");

/// The magic bytes at the start of a blob.
pub const BLOB_MAGIC: [u8; 4] = *b"SLFD";
/// The format version this decoder writes with schedules (and reads, with version 1).
pub const BLOB_VERSION: u16 = 2;
/// The format version without schedules, which this decoder reads and writes too.
pub const BLOB_VERSION_UNSCHEDULED: u16 = 1;
/// Header length in bytes.
pub const HEADER_LEN: usize = 24;
/// Checksum length in bytes.
pub const CHECKSUM_LEN: usize = 4;

const CRC32: Crc<u32> = Crc::<u32>::new(&CRC_32_ISO_HDLC);

// Header field offsets.
const VERSION_AT: usize = 4;
const RESERVED_AT: usize = 6;
const DIMS_AT: usize = 8;
const MEMBERS_AT: usize = 18;
const PAYLOAD_LEN_AT: usize = 20;

/// Bytes of one member of a `PS x PT x PU x PV x B` dictionary.
pub const fn member_len(dims: [usize; 5]) -> usize {
    4 * (dims[0] * dims[0] + dims[1] * dims[1] + dims[2] * dims[2] + dims[3] * dims[3] + dims[4] * dims[4])
}

/// Total bytes of a blob of `members` members.
pub const fn blob_len(dims: [usize; 5], members: usize) -> usize {
    HEADER_LEN + members * member_len(dims) + CHECKSUM_LEN
}

/// Bytes of one schedule of `steps` steps in a blob.
pub const fn schedule_len(dims: [usize; 5], steps: usize) -> usize {
    4 + 8 * steps + 4 * (dims[0] + dims[1] + dims[2] + dims[3] + dims[4])
}

/// Total bytes of a blob of `members` members and schedules of the given steps (cold, warm,
/// alone).
pub const fn scheduled_blob_len(dims: [usize; 5], members: usize, steps: [usize; 3]) -> usize {
    blob_len(dims, members) + schedule_len(dims, steps[0]) + schedule_len(dims, steps[1]) + schedule_len(dims, steps[2])
}

fn u16_at(b: &[u8], at: usize) -> u16 {
    match b.get(at..at + 2) {
        Some(&[x, y]) => u16::from_le_bytes([x, y]),
        _ => 0,
    }
}

/// The patch dimensions `[PS, PT, PU, PV, B]` a blob's header states, read without
/// validating the rest (so a caller can pick the [`Ensemble`] type to check it with);
/// `None` for a blob too short to hold a header or without the magic bytes.
pub fn dims(blob: &[u8]) -> Option<[usize; 5]> {
    if blob.len() < HEADER_LEN || blob.get(..4) != Some(&BLOB_MAGIC[..]) {
        return None;
    }
    let mut dims = [0usize; 5];
    for (i, d) in dims.iter_mut().enumerate() {
        *d = usize::from(u16_at(blob, DIMS_AT + 2 * i));
    }
    Some(dims)
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    match b.get(at..at + 4) {
        Some(&[w, x, y, z]) => u32::from_le_bytes([w, x, y, z]),
        _ => 0,
    }
}

/// Copies `bytes` into `buf` at `at`, if they fit (the writers' offsets always do).
fn put(buf: &mut [u8], at: usize, bytes: &[u8]) {
    if let Some(dst) = buf.get_mut(at..at + bytes.len()) {
        dst.copy_from_slice(bytes);
    }
}

fn read_matrix<E: Mode>(bytes: &[u8]) -> ModeMatrix<E> {
    let mut m = E::ZERO_MATRIX;
    let mut words = bytes.as_chunks::<4>().0.iter();
    for row in m.iter_mut() {
        for (x, w) in row.iter_mut().zip(words.by_ref()) {
            *x = f32::from_le_bytes(*w);
        }
    }
    m
}

fn write_matrix<E: Mode>(m: &ModeMatrix<E>, out: &mut [u8]) -> usize {
    let mut words = out.as_chunks_mut::<4>().0.iter_mut();
    for row in m.iter() {
        for (x, w) in row.iter().zip(words.by_ref()) {
            *w = x.to_le_bytes();
        }
    }
    4 * E::D * E::D
}

fn f32_at(b: &[u8], at: usize) -> f32 {
    f32::from_bits(u32_at(b, at))
}

/// One schedule from `bytes`; returns it and its length in bytes.
fn read_schedule<S: Shape>(bytes: &[u8]) -> Result<(Schedule<S>, usize), DictionaryError> {
    let steps = usize::from(u16_at(bytes, 0));
    let len = schedule_len([S::PS, S::PT, S::PU, S::PV, S::B], steps);
    if bytes.len() < 4 || steps == 0 || steps > MAX_STEPS || bytes.len() < len {
        return Err(DictionaryError::BadSchedule { part: "steps" });
    }
    let fill_start = match u16_at(bytes, 2) {
        0 => false,
        1 => true,
        _ => return Err(DictionaryError::BadSchedule { part: "start" }),
    };
    let (mut sigma, mut mu) = ([0.0f32; MAX_STEPS], [0.0f32; MAX_STEPS]);
    for t in 0..steps {
        (sigma[t], mu[t]) = (f32_at(bytes, 4 + 4 * t), f32_at(bytes, 4 + 4 * (steps + t)));
    }
    let mut weights = Weights::ONES;
    let mut at = 4 + 8 * steps;
    for mode in weights.modes_mut() {
        for w in mode {
            *w = f32_at(bytes, at);
            at += 4;
        }
    }
    let schedule = Schedule::new(sigma.get(..steps).unwrap_or(&[]), mu.get(..steps).unwrap_or(&[]), weights)?;
    Ok((schedule.with_fill_start(fill_start), len))
}

/// The cold, the warm and the alone schedule, which must fill `bytes` exactly.
fn read_schedules<S: Shape>(bytes: &[u8]) -> Result<Schedules<S>, DictionaryError> {
    let (cold, a) = read_schedule(bytes)?;
    let (warm, b) = read_schedule(bytes.get(a..).unwrap_or(&[]))?;
    let (alone, c) = read_schedule(bytes.get(a + b..).unwrap_or(&[]))?;
    if a + b + c != bytes.len() {
        return Err(DictionaryError::BadSchedule { part: "steps" });
    }
    Ok(Schedules { cold, warm, alone })
}

/// Writes one schedule at the start of `out`; returns its length.
fn write_schedule<S: Shape>(s: &Schedule<S>, out: &mut [u8]) -> usize {
    put(out, 0, &(s.len() as u16).to_le_bytes());
    put(out, 2, &u16::from(s.fill_start()).to_le_bytes());
    let mut at = 4;
    let weights = s.weights().modes();
    for x in s.sigma().iter().chain(s.mu()).chain(weights.iter().flat_map(|w| w.iter())) {
        put(out, at, &x.to_le_bytes());
        at += 4;
    }
    at
}

/// A validated blob of K >= 1 members, read in place from flash.
#[derive(Clone, Copy, Debug)]
pub struct Ensemble<'a, S: Shape> {
    shape: PhantomData<S>,
    payload: &'a [u8],
    members: u16,
    /// The schedules' bytes (version 2), validated.
    schedules: Option<&'a [u8]>,
}

impl<'a, S: Shape> Ensemble<'a, S> {
    const DIMS: [usize; 5] = [S::PS, S::PT, S::PU, S::PV, S::B];
    const MEMBER_LEN: usize = member_len(Self::DIMS);

    /// Checks a blob completely (see the module docs for the order of checks).
    ///
    /// # Errors
    /// The first [`DictionaryError`] the blob fails.
    pub fn new(blob: &'a [u8]) -> Result<Self, DictionaryError> {
        let len = blob.len();
        if len < HEADER_LEN + CHECKSUM_LEN {
            return Err(DictionaryError::TooShort { len: len as u32 });
        }
        if blob.get(..4) != Some(&BLOB_MAGIC[..]) {
            return Err(DictionaryError::BadMagic);
        }
        let version = u16_at(blob, VERSION_AT);
        if version != BLOB_VERSION && version != BLOB_VERSION_UNSCHEDULED {
            return Err(DictionaryError::UnsupportedVersion { found: version });
        }
        if u16_at(blob, RESERVED_AT) != 0 {
            return Err(DictionaryError::ReservedNotZero);
        }
        let mut dims = [0u16; 5];
        for (i, d) in dims.iter_mut().enumerate() {
            *d = u16_at(blob, DIMS_AT + 2 * i);
        }
        if dims.iter().zip(Self::DIMS).any(|(&a, b)| a as usize != b) {
            return Err(DictionaryError::ShapeMismatch { found: dims });
        }
        let members = u16_at(blob, MEMBERS_AT);
        if members == 0 {
            return Err(DictionaryError::MemberCount { found: 0 });
        }
        let members_len = members as usize * Self::MEMBER_LEN;
        // Version 2 adds the schedules after the members: at least two empty ones' headers.
        let least = if version == BLOB_VERSION { members_len + 3 * schedule_len(Self::DIMS, 1) } else { members_len };
        let payload_len = u32_at(blob, PAYLOAD_LEN_AT) as usize;
        let expected = HEADER_LEN + payload_len.max(least) + CHECKSUM_LEN;
        let fits = if version == BLOB_VERSION { payload_len >= least } else { payload_len == members_len };
        if !fits || len != expected {
            let expected = HEADER_LEN + least + CHECKSUM_LEN;
            return Err(DictionaryError::LengthMismatch { expected: expected as u32, found: len as u32 });
        }
        let body_len = len - CHECKSUM_LEN;
        let stored = u32_at(blob, body_len);
        let computed = CRC32.checksum(blob.get(..body_len).unwrap_or(&[]));
        if stored != computed {
            return Err(DictionaryError::Checksum { stored, computed });
        }
        let schedules = (version == BLOB_VERSION).then(|| blob.get(HEADER_LEN + members_len..body_len).unwrap_or(&[]));
        let ensemble = Self {
            shape: PhantomData,
            payload: blob.get(HEADER_LEN..HEADER_LEN + members_len).unwrap_or(&[]),
            members,
            schedules,
        };
        for m in 0..members {
            ensemble.factors(m).validate(m)?;
        }
        if let Some(bytes) = schedules {
            read_schedules::<S>(bytes)?;
        }
        Ok(ensemble)
    }

    /// The trained schedules of a version 2 blob (validated by [`new`](Self::new)); `None`
    /// for a version 1 blob, whose solves take the hand-set schedule.
    pub fn schedules(&self) -> Option<Schedules<S>> {
        self.schedules.and_then(|b| read_schedules::<S>(b).ok())
    }

    /// Number of members K.
    pub fn len(&self) -> usize {
        self.members as usize
    }

    /// Always false: a validated ensemble has at least one member.
    pub fn is_empty(&self) -> bool {
        self.members == 0
    }

    fn factors(&self, member: u16) -> Factors<S> {
        let start = member as usize * Self::MEMBER_LEN;
        let bytes = self.payload.get(start..start + Self::MEMBER_LEN).unwrap_or(&[]);
        let mut at = 0;
        let mut next = |n: usize| {
            let s = bytes.get(at..at + 4 * n * n).unwrap_or(&[]);
            at += 4 * n * n;
            s
        };
        Factors {
            m1: read_matrix::<S::S>(next(S::PS)),
            m2: read_matrix::<S::T>(next(S::PT)),
            m3: read_matrix::<S::U>(next(S::PU)),
            m4: read_matrix::<S::V>(next(S::PV)),
            m5: read_matrix::<S::Bands>(next(S::B)),
        }
    }

    /// Member `index`, copied out of the blob (validated by [`new`](Self::new)).
    ///
    /// # Errors
    /// [`DictionaryError::NoSuchMember`] past the end.
    pub fn member(&self, index: usize) -> Result<Dictionary<S>, DictionaryError> {
        if index >= self.len() {
            return Err(DictionaryError::NoSuchMember {
                index: index.min(u16::MAX as usize) as u16,
                members: self.members,
            });
        }
        Ok(Dictionary::from_validated(self.factors(index as u16)))
    }
}

impl<S: Shape> Dictionary<S> {
    /// Reads a blob that holds exactly one member.
    ///
    /// # Errors
    /// Any [`Ensemble::new`] error, or [`DictionaryError::MemberCount`] for K != 1.
    pub fn from_blob(blob: &[u8]) -> Result<Self, DictionaryError> {
        let e = Ensemble::<S>::new(blob)?;
        if e.len() != 1 {
            return Err(DictionaryError::MemberCount { found: e.members });
        }
        e.member(0)
    }
}

/// Writes `members` as a blob into `out`; returns the number of bytes written.
///
/// # Errors
/// [`DictionaryError::MemberCount`] for no members (or more than 65535),
/// [`DictionaryError::BufferTooSmall`] when `out` is shorter than [`blob_len`].
pub fn write_blob<S: Shape>(members: &[Dictionary<S>], out: &mut [u8]) -> Result<usize, DictionaryError> {
    write_blob_scheduled(members, None, out)
}

/// Writes `members` and, if given, their trained `schedules` as a blob into `out` (version
/// 2 with schedules, 1 without); returns the number of bytes written
/// ([`scheduled_blob_len`], or [`blob_len`] without schedules).
///
/// # Errors
/// As [`write_blob`].
pub fn write_blob_scheduled<S: Shape>(
    members: &[Dictionary<S>],
    schedules: Option<&Schedules<S>>,
    out: &mut [u8],
) -> Result<usize, DictionaryError> {
    let dims = [S::PS, S::PT, S::PU, S::PV, S::B];
    if members.is_empty() || members.len() > u16::MAX as usize {
        return Err(DictionaryError::MemberCount { found: members.len().min(u16::MAX as usize) as u16 });
    }
    let total = match schedules {
        Some(s) => scheduled_blob_len(dims, members.len(), [s.cold.len(), s.warm.len(), s.alone.len()]),
        None => blob_len(dims, members.len()),
    };
    let Some(out) = out.get_mut(..total) else {
        return Err(DictionaryError::BufferTooSmall { needed: total as u32 });
    };
    out.fill(0);
    // Every offset below is within `total` by construction; `put` and `get_mut` keep a
    // bounds failure from being a panic path in any build profile.
    let (header, rest) = out.split_at_mut(HEADER_LEN.min(total));
    put(header, 0, &BLOB_MAGIC);
    let version = if schedules.is_some() { BLOB_VERSION } else { BLOB_VERSION_UNSCHEDULED };
    put(header, VERSION_AT, &version.to_le_bytes());
    for (i, d) in dims.iter().enumerate() {
        put(header, DIMS_AT + 2 * i, &(*d as u16).to_le_bytes());
    }
    put(header, MEMBERS_AT, &(members.len() as u16).to_le_bytes());
    let payload_len = total - HEADER_LEN - CHECKSUM_LEN;
    put(header, PAYLOAD_LEN_AT, &(payload_len as u32).to_le_bytes());
    let mut at = 0;
    for m in members {
        let d = &m.d;
        at += write_matrix::<S::S>(&d.m1, rest.get_mut(at..).unwrap_or_default());
        at += write_matrix::<S::T>(&d.m2, rest.get_mut(at..).unwrap_or_default());
        at += write_matrix::<S::U>(&d.m3, rest.get_mut(at..).unwrap_or_default());
        at += write_matrix::<S::V>(&d.m4, rest.get_mut(at..).unwrap_or_default());
        at += write_matrix::<S::Bands>(&d.m5, rest.get_mut(at..).unwrap_or_default());
    }
    if let Some(s) = schedules {
        for schedule in [&s.cold, &s.warm, &s.alone] {
            at += write_schedule(schedule, rest.get_mut(at..).unwrap_or_default());
        }
    }
    let body_len = total - CHECKSUM_LEN;
    let crc = CRC32.checksum(out.get(..body_len).unwrap_or_default());
    put(out, body_len, &crc.to_le_bytes());
    Ok(total)
}
