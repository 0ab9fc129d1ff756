//! DCT tables, dictionary validation, and the blob format: round trip and every corrupt case.

mod common;

use common::*;
use slf_firmware::FullViewShape;
use slf_firmware::PaperShape;
use slf_firmware::blob::write_blob;
use slf_firmware::blob::{BLOB_VERSION, HEADER_LEN, blob_len};
use slf_firmware::dct::dct_matrix;
use slf_firmware::dictionary::Factors;
use slf_firmware::dictionary::{ORTHONORMAL_TOLERANCE, orthonormality_error};
use slf_firmware::{Dictionary, DictionaryError, Ensemble};

type Dict = Dictionary<PaperShape>;
const DIMS: [usize; 5] = [5, 5, 4, 4, 13];

fn check_dct<const D: usize>() {
    let m = dct_matrix::<D>();
    assert!(orthonormality_error(&m) <= 1e-6, "DCT {D} not orthonormal: {}", orthonormality_error(&m));
    for (k, row) in m.iter().enumerate() {
        let a = if k == 0 { (1.0 / D as f64).sqrt() } else { (2.0 / D as f64).sqrt() };
        for (n, &x) in row.iter().enumerate() {
            let want = a * (std::f64::consts::PI * (2 * n + 1) as f64 * k as f64 / (2 * D) as f64).cos();
            assert!((f64::from(x) - want).abs() < 1e-7, "DCT {D}[{k}][{n}] = {x}, want {want}");
        }
    }
}

#[test]
fn dct_matrices_are_the_orthonormal_dct_ii() {
    check_dct::<1>();
    check_dct::<2>();
    check_dct::<3>();
    check_dct::<4>();
    check_dct::<5>();
    check_dct::<8>();
    check_dct::<13>();
    check_dct::<16>();
    check_dct::<31>();
}

/// The DCT dictionary is a compile-time constant: usable in a `static` (a flash table).
static DCT: Dict = Dictionary::dct();

#[test]
fn dct_dictionary_is_valid_and_static() {
    assert!(Dict::new(DCT.synthesis().clone()).is_ok());
    // Synthesis matrices have the cosine atoms as columns.
    assert_eq!(DCT.synthesis().m5[3][1], dct_matrix::<13>()[1][3]);
}

#[test]
fn new_rejects_non_finite_and_non_orthonormal() {
    let mut f = DCT.synthesis().clone();
    f.m3[1][2] = f32::NAN;
    assert_eq!(Dict::new(f).unwrap_err(), DictionaryError::NonFinite { member: 0, mode: 3 });
    let mut f = DCT.synthesis().clone();
    f.m5[0][0] += 1e-3;
    assert_eq!(Dict::new(f).unwrap_err(), DictionaryError::NotOrthonormal { member: 0, mode: 5 });
    // Within the tolerance is fine.
    let mut f = DCT.synthesis().clone();
    f.m5[0][0] += ORTHONORMAL_TOLERANCE / 10.0;
    assert!(Dict::new(f).is_ok());
}

fn members() -> Vec<Dict> {
    vec![random_dictionary(1), Dictionary::dct(), random_dictionary(2)]
}

fn blob_of(members: &[Dict]) -> Vec<u8> {
    let mut out = vec![0u8; blob_len(DIMS, members.len())];
    let n = write_blob(members, &mut out).unwrap();
    assert_eq!(n, out.len());
    out
}

#[test]
fn blob_round_trip() {
    let m = members();
    let blob = blob_of(&m);
    assert_eq!(&blob[..4], b"SLFD");
    let e = Ensemble::<PaperShape>::new(&blob).unwrap();
    assert_eq!(e.len(), 3);
    for (i, want) in m.iter().enumerate() {
        assert_eq!(&e.member(i).unwrap(), want, "member {i}");
    }
    // Writing what was read gives the same bytes.
    let again: Vec<Dict> = (0..e.len()).map(|i| e.member(i).unwrap()).collect();
    assert_eq!(blob_of(&again), blob);
    // A single-member blob reads as a Dictionary.
    let one = blob_of(&m[1..2]);
    assert_eq!(Dict::from_blob(&one).unwrap(), m[1]);
}

#[test]
fn a_blobs_header_names_its_patch_before_it_is_validated() {
    use slf_firmware::blob::dims;
    assert_eq!(dims(&blob_of(&members())), Some(DIMS));
    assert_eq!(dims(slf_firmware::DEFAULT_ENSEMBLE), Some([5, 5, 4, 4, 13]));
    assert_eq!(dims(slf_firmware::DEFAULT_FULL_VIEW_ENSEMBLE), Some([5, 5, 5, 5, 13]));
    // A header that states another shape is read as stated (the checked constructor then
    // refuses it for the wrong type); too short or without the magic: nothing.
    let mut other = blob_of(&members());
    other[8..10].copy_from_slice(&7u16.to_le_bytes());
    assert_eq!(dims(&other), Some([7, 5, 4, 4, 13]));
    assert_eq!(dims(&other[..HEADER_LEN - 1]), None);
    assert_eq!(dims(b"NOPE and some more bytes than a header"), None);
    assert_eq!(dims(&[]), None);
}

/// Recomputes the trailing CRC so a corruption reaches the checks after it.
fn reseal(blob: &mut [u8]) {
    let body = blob.len() - 4;
    let crc = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC).checksum(&blob[..body]);
    blob[body..].copy_from_slice(&crc.to_le_bytes());
}

fn put_f32(blob: &mut [u8], at: usize, x: f32) {
    blob[at..at + 4].copy_from_slice(&x.to_le_bytes());
}

#[test]
fn each_corrupt_blob_gets_its_own_error() {
    let good = blob_of(&members());
    let read = |b: &[u8]| Ensemble::<PaperShape>::new(b).map(|_| ()).unwrap_err();
    let member_bytes = 4 * (25 + 25 + 16 + 16 + 169);

    assert_eq!(read(&good[..10]), DictionaryError::TooShort { len: 10 });

    let mut b = good.clone();
    b[0] = b'X';
    assert_eq!(read(&b), DictionaryError::BadMagic);

    let mut b = good.clone();
    b[4..6].copy_from_slice(&(BLOB_VERSION + 1).to_le_bytes());
    assert_eq!(read(&b), DictionaryError::UnsupportedVersion { found: BLOB_VERSION + 1 });

    let mut b = good.clone();
    b[6] = 1;
    assert_eq!(read(&b), DictionaryError::ReservedNotZero);

    let mut b = good.clone();
    b[16..18].copy_from_slice(&12u16.to_le_bytes());
    assert_eq!(read(&b), DictionaryError::ShapeMismatch { found: [5, 5, 4, 4, 12] });

    let mut b = good.clone();
    b[18..20].copy_from_slice(&0u16.to_le_bytes());
    assert_eq!(read(&b), DictionaryError::MemberCount { found: 0 });

    // Truncated body, and a header that claims more members than the blob holds.
    let b = &good[..good.len() - 8];
    assert_eq!(read(b), DictionaryError::LengthMismatch { expected: good.len() as u32, found: b.len() as u32 });
    let mut b = good.clone();
    b[18..20].copy_from_slice(&4u16.to_le_bytes());
    assert!(matches!(read(&b), DictionaryError::LengthMismatch { .. }));

    let mut b = good.clone();
    b[HEADER_LEN + 17] ^= 0x40;
    assert!(matches!(read(&b), DictionaryError::Checksum { .. }));

    // Member 1 (the DCT), mode 2: its first entry becomes NaN, checksum resealed.
    let mut b = good.clone();
    put_f32(&mut b, HEADER_LEN + member_bytes + 4 * 25, f32::NAN);
    reseal(&mut b);
    assert_eq!(read(&b), DictionaryError::NonFinite { member: 1, mode: 2 });
    put_f32(&mut b, HEADER_LEN + member_bytes + 4 * 25, f32::INFINITY);
    reseal(&mut b);
    assert_eq!(read(&b), DictionaryError::NonFinite { member: 1, mode: 2 });

    // Member 2, mode 5: one entry off by 1e-2.
    let mut b = good.clone();
    let at = HEADER_LEN + 2 * member_bytes + 4 * (25 + 25 + 16 + 16) + 4 * 20;
    let x = f32::from_le_bytes(b[at..at + 4].try_into().unwrap());
    put_f32(&mut b, at, x + 1e-2);
    reseal(&mut b);
    assert_eq!(read(&b), DictionaryError::NotOrthonormal { member: 2, mode: 5 });

    // A blob for another patch shape.
    let other: Vec<Dictionary<FullViewShape>> = vec![Dictionary::dct()];
    let mut ob = vec![0u8; blob_len([5, 5, 5, 5, 13], 1)];
    write_blob(&other, &mut ob).unwrap();
    assert_eq!(read(&ob), DictionaryError::ShapeMismatch { found: [5, 5, 5, 5, 13] });

    // Member index and member count errors.
    let e = Ensemble::<PaperShape>::new(&good).unwrap();
    assert_eq!(e.member(3).unwrap_err(), DictionaryError::NoSuchMember { index: 3, members: 3 });
    assert_eq!(Dict::from_blob(&good).unwrap_err(), DictionaryError::MemberCount { found: 3 });

    // Writer errors.
    let mut small = vec![0u8; 100];
    assert_eq!(
        write_blob(&members(), &mut small).unwrap_err(),
        DictionaryError::BufferTooSmall { needed: good.len() as u32 }
    );
    assert_eq!(write_blob::<PaperShape>(&[], &mut small).unwrap_err(), DictionaryError::MemberCount { found: 0 });

    // Every error prints a message.
    assert!(DictionaryError::Checksum { stored: 1, computed: 2 }.to_string().contains("checksum"));
}

#[test]
fn factors_report_the_mode_that_is_wrong() {
    let f: Factors<PaperShape> = DCT.synthesis().clone();
    assert_eq!(f.first_non_finite(), None);
    assert!(f.orthonormality_errors().iter().all(|&e| e <= 1e-6));
}

#[test]
fn the_dct_symmetry_is_found_where_it_holds_and_used_correctly() {
    use slf_firmware::dictionary::{has_parity, transpose};
    use slf_firmware::transform::{analyze, synthesize};
    // The DCT-II's rows are even / odd about their middle, so its transforms fold.
    assert_eq!(Dict::dct().parity(), [true; 4]);
    assert!(has_parity(&dct_matrix::<13>()) && has_parity(&dct_matrix::<7>()) && has_parity(&dct_matrix::<1>()));
    // Built from its matrices (as a blob member is), the DCT is found symmetric again.
    assert_eq!(Dict::new(Dict::dct().synthesis().clone()).unwrap().parity(), [true; 4]);
    assert_eq!(random_dictionary::<PaperShape>(3).parity(), [false; 4]);
    // Two atoms swapped: still orthonormal, no longer even / odd in order.
    let mut f = Dict::dct().synthesis().clone();
    let t = transpose(&f.m2);
    f.m2 = transpose(&[t[0], t[2], t[1], t[3], t[4]]);
    assert_eq!(Dict::new(f).unwrap().parity(), [true, false, true, true]);
    // A random dictionary with the DCT in mode 3 only folds mode 3, and its transforms still
    // match the dense Kronecker matrix (f64) to 1e-5.
    let mut f = random_dictionary::<PaperShape>(4).synthesis().clone();
    f.m3 = transpose(&dct_matrix::<4>());
    let mixed = Dict::new(f).unwrap();
    assert_eq!(mixed.parity(), [false, false, true, false]);
    let (k, n) = dense_kronecker(mixed.synthesis());
    let (kt, _) = dense_kronecker(mixed.analysis());
    let mut r = rng(5);
    let s: Vec<f32> = (0..n).map(|_| rand::Rng::random_range(&mut r, -1.0f32..1.0)).collect();
    let (mut a, mut x) = (Box::new([0.0f32; 5200]), Box::new([0.0f32; 5200]));
    a.copy_from_slice(&s);
    synthesize(&mixed, &mut a, &mut x);
    assert!(rel_err(&x[..], &dense_apply(&k, n, &s)) <= 1e-5);
    a.copy_from_slice(&s);
    analyze(&mixed, &mut a, &mut x);
    assert!(rel_err(&x[..], &dense_apply(&kt, n, &s)) <= 1e-5);
}
