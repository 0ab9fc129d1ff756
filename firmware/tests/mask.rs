//! Mask families: reproducible from a seed, k distinct bands per position, the structure
//! each family promises, explicit periodic tiles, and defect lists.

use slf_firmware::Fixed;
use std::collections::HashSet;

use slf_firmware::{BandTile, DefectList, LensletSize, Mask, MaskFamily, Pixel, SensingError};

const L5: LensletSize = LensletSize { rows: 5, cols: 5 };

fn all_families(seed: u64, k: u8) -> [Mask<'static>; 3] {
    [
        Mask::kronecker(seed, k, 13, L5, (5, 5)).unwrap(),
        Mask::lenslet(seed, k, 13, L5).unwrap(),
        Mask::pixel(seed, k, 13, L5).unwrap(),
    ]
}

#[test]
fn every_position_sees_k_distinct_bands() {
    for k in 1..=13u8 {
        for mask in all_families(3, k) {
            for row in 0..60 {
                for col in 0..60 {
                    let bands = mask.bands_at(row, col);
                    assert_eq!(bands.len(), k as usize);
                    let set: HashSet<u8> = bands.iter().copied().collect();
                    assert_eq!(set.len(), k as usize, "{:?} k {k} at ({row}, {col})", mask.family());
                    assert!(bands.iter().all(|&b| b < 13));
                    assert_eq!(mask.band(k as usize - 1, row, col), Some(bands[k as usize - 1]));
                    assert_eq!(mask.band(k as usize, row, col), None);
                }
            }
        }
    }
}

#[test]
fn seeded_masks_are_reproducible_and_seed_dependent() {
    for (a, b) in all_families(5, 3).iter().zip(all_families(5, 3).iter()) {
        for p in 0..500 {
            assert_eq!(a.bands_at(p / 7, p % 97), b.bands_at(p / 7, p % 97));
        }
    }
    for (a, b) in all_families(5, 3).iter().zip(all_families(6, 3).iter()) {
        let differ = (0..2500).filter(|p| a.bands_at(p / 50, p % 50) != b.bands_at(p / 50, p % 50)).count();
        assert!(differ > 100, "{:?}: only {differ} positions differ between seeds", a.family());
    }
}

#[test]
fn families_have_their_structure() {
    let [kron, lenslet, pixel] = all_families(9, 2);
    // Kronecker: constant over a 5 x 5-lenslet block (25 x 25 pixels).
    for row in 0..50 {
        for col in 0..50 {
            let block = ((row / 25) * 25, (col / 25) * 25);
            assert_eq!(kron.bands_at(row, col), kron.bands_at(block.0, block.1));
            let l = ((row / 5) * 5, (col / 5) * 5);
            assert_eq!(lenslet.bands_at(row, col), lenslet.bands_at(l.0, l.1));
        }
    }
    // Blocks, lenslets and pixels differ from each other at their own scale.
    let distinct = |f: &dyn Fn(usize) -> (usize, usize), m: &Mask| {
        (0..100).map(f).map(|(r, c)| m.bands_at(r, c).to_vec()).collect::<HashSet<_>>().len()
    };
    assert!(distinct(&|i| (25 * (i / 10), 25 * (i % 10)), &kron) > 30);
    assert!(distinct(&|i| (5 * (i / 10), 5 * (i % 10)), &lenslet) > 30);
    assert!(distinct(&|i| (i / 10, i % 10), &pixel) > 30);
    // Bands are spread evenly over many positions (a bias would show here).
    let mut hist = [0usize; 13];
    for p in 0..13_000 {
        hist[pixel.bands_at(p / 130, p % 130)[0] as usize] += 1;
    }
    assert!(hist.iter().all(|&h| (800..1200).contains(&h)), "{hist:?}");
}

#[test]
fn explicit_tiles_repeat_with_their_period() {
    // 2 snapshots of a 2 x 3 tile.
    let bands = [0u8, 1, 2, 3, 4, 5, /* snapshot 1 */ 6, 7, 8, 9, 10, 11];
    let tile = BandTile::new(2, 3, 2, 13, &bands).unwrap();
    let pixel = Mask::pixel_tile(tile, 13, L5).unwrap();
    assert_eq!(pixel.snapshots(), 2);
    assert_eq!(pixel.seed(), None);
    for row in 0..12 {
        for col in 0..12 {
            let cell = (row % 2) * 3 + col % 3;
            assert_eq!(pixel.bands_at(row, col).as_slice(), &[bands[cell], bands[6 + cell]]);
        }
    }
    // The lenslet family's period is in lenslets.
    let lenslet = Mask::lenslet_tile(tile, 13, L5).unwrap();
    for row in 0..30 {
        for col in 0..30 {
            let cell = ((row / 5) % 2) * 3 + (col / 5) % 3;
            assert_eq!(lenslet.bands_at(row, col).as_slice(), &[bands[cell], bands[6 + cell]]);
        }
    }
}

#[test]
fn bad_masks_are_typed_errors() {
    assert_eq!(Mask::pixel(1, 0, 13, L5).unwrap_err(), SensingError::Snapshots { snapshots: 0, bands: 13 });
    assert_eq!(Mask::pixel(1, 14, 13, L5).unwrap_err(), SensingError::Snapshots { snapshots: 14, bands: 13 });
    assert_eq!(Mask::pixel(1, 1, 0, L5).unwrap_err(), SensingError::Bands { bands: 0 });
    assert_eq!(Mask::pixel(1, 1, 40, L5).unwrap_err(), SensingError::Bands { bands: 40 });
    assert_eq!(Mask::lenslet(1, 1, 13, LensletSize { rows: 0, cols: 5 }).unwrap_err(), SensingError::EmptySize);
    assert_eq!(Mask::kronecker(1, 1, 13, L5, (0, 5)).unwrap_err(), SensingError::EmptySize);
    assert_eq!(BandTile::new(2, 2, 1, 13, &[0, 1, 2]).unwrap_err(), SensingError::TileLength { expected: 4, found: 3 });
    assert_eq!(BandTile::new(0, 2, 1, 13, &[]).unwrap_err(), SensingError::EmptySize);
    assert_eq!(
        BandTile::new(1, 2, 1, 13, &[0, 13]).unwrap_err(),
        SensingError::BandOutOfRange { band: 13, row: 0, col: 1 }
    );
    // Repeated band across snapshots at cell (1, 0).
    assert_eq!(
        BandTile::new(2, 1, 2, 13, &[0, 5, 1, 5]).unwrap_err(),
        SensingError::RepeatedBand { band: 5, row: 1, col: 0 }
    );
    // A tile checked for 13 bands is re-checked against the mask's band count.
    let t = BandTile::new(1, 2, 1, 13, &[0, 9]).unwrap();
    assert_eq!(Mask::pixel_tile(t, 8, L5).unwrap_err(), SensingError::BandOutOfRange { band: 9, row: 0, col: 1 });
    assert!(SensingError::RepeatedBand { band: 5, row: 1, col: 0 }.to_string().contains("repeated"));
}

#[test]
fn kronecker_phi_is_the_papers_form() {
    let mask = Mask::kronecker(4, 3, 13, L5, (5, 5)).unwrap();
    let phi = mask.kronecker_phi::<Fixed<5>, Fixed<5>, Fixed<4>, Fixed<4>>(30, 60).unwrap();
    assert_eq!(phi.bands, mask.bands_at(30, 60));
    // Row shuffles are permutations, the same for every block.
    let mut p = phi.shuffle3;
    p.sort();
    assert_eq!(p, [0, 1, 2, 3]);
    let mut p = phi.shuffle1;
    p.sort();
    assert_eq!(p, [0, 1, 2, 3, 4]);
    assert_eq!(mask.kronecker_phi::<Fixed<5>, Fixed<5>, Fixed<4>, Fixed<4>>(0, 0).unwrap().shuffle1, phi.shuffle1);
    assert_eq!(
        mask.kronecker_phi::<Fixed<4>, Fixed<4>, Fixed<4>, Fixed<4>>(0, 0).unwrap_err(),
        SensingError::BlockMismatch
    );
    let pixel = Mask::pixel(4, 3, 13, L5).unwrap();
    assert_eq!(
        pixel.kronecker_phi::<Fixed<5>, Fixed<5>, Fixed<4>, Fixed<4>>(0, 0).unwrap_err(),
        SensingError::NotKronecker
    );
    assert_eq!(pixel.family(), MaskFamily::Pixel);
}

#[test]
fn defect_lists_are_checked_and_found() {
    let px = [Pixel { row: 0, col: 3 }, Pixel { row: 2, col: 1 }, Pixel { row: 2, col: 7 }];
    let d = DefectList::new(&px).unwrap();
    assert!(d.contains(2, 7) && d.contains(0, 3));
    assert!(!d.contains(2, 6) && !d.contains(70_000, 3));
    assert_eq!(d.len(), 3);
    let unsorted = [Pixel { row: 2, col: 1 }, Pixel { row: 0, col: 3 }];
    assert_eq!(DefectList::new(&unsorted).unwrap_err(), SensingError::DefectsUnsorted { index: 1 });
    let dup = [Pixel { row: 2, col: 1 }, Pixel { row: 2, col: 1 }];
    assert_eq!(DefectList::new(&dup).unwrap_err(), SensingError::DefectsUnsorted { index: 1 });
    assert!(DefectList::EMPTY.is_empty());
}
