//! Damaged snapshots are refused (issue 16 item 5): a checksum over the data and the
//! metadata notices any changed byte; the data file must lie beside the metadata.

mod common;

use serde_json::json;
use std::path::{Path, PathBuf};
use talus::io::snapshot::{self, SnapshotError};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("talus-snapshots-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A snapshot of a small pile with contacts, written into `dir`; its JSON path.
fn written(dir: &Path) -> PathBuf {
    // A row of disks touching each other on a floor, a pentagon resting on them (the
    // snapshot's corner table).
    let v = common::disks_and_a_pentagon();
    let mut s = common::sim(&v);
    s.advance(400).unwrap();
    assert!(!s.contacts.is_empty(), "the snapshot should have contacts");
    snapshot::write(&s, dir, "snap").unwrap()
}

/// A deterministic stream of positions and byte changes.
fn flips(n: usize, len: usize, seed: u64) -> impl Iterator<Item = (usize, u8)> {
    let mut x = seed;
    std::iter::repeat_with(move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        ((x >> 8) as usize % len, 1 + (x % 255) as u8)
    })
    .take(n)
}

#[test]
fn every_changed_byte_of_a_snapshot_is_refused() {
    let dir = tmp("flips");
    let json_path = written(&dir);
    let bin_path = dir.join("snap.bin");
    let good = snapshot::read(&json_path).expect("an intact snapshot reads");
    let (bin, text) = (
        std::fs::read(&bin_path).unwrap(),
        std::fs::read(&json_path).unwrap(),
    );
    for (at, x) in flips(500, bin.len(), 1) {
        let mut b = bin.clone();
        b[at] ^= x;
        std::fs::write(&bin_path, &b).unwrap();
        match snapshot::read(&json_path) {
            Err(SnapshotError::Checksum(_)) => {}
            other => panic!("a change at byte {at} of the data: {other:?}"),
        }
    }
    std::fs::write(&bin_path, &bin).unwrap();
    let mut refused = 0;
    for (at, x) in flips(500, text.len(), 2) {
        let mut t = text.clone();
        t[at] ^= x;
        std::fs::write(&json_path, &t).unwrap();
        // A change to the metadata either breaks it or is noticed; only one that leaves
        // every value as it was (whitespace for whitespace) may read, and then reads
        // the same snapshot.
        match snapshot::read(&json_path) {
            Ok(s) => assert_eq!(s, good, "a change at byte {at} of the metadata read"),
            Err(e) => {
                refused += 1;
                let msg = e.to_string();
                assert!(!msg.is_empty());
            }
        }
    }
    assert!(refused >= 480, "{refused} of 500 metadata changes refused");
}

#[test]
fn a_snapshot_without_its_checksum_or_pointing_elsewhere_is_refused() {
    let dir = tmp("edited");
    let json_path = written(&dir);
    let meta: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&json_path).unwrap()).unwrap();
    let rewrite = |edit: &dyn Fn(&mut serde_json::Value)| {
        let mut m = meta.clone();
        edit(&mut m);
        std::fs::write(&json_path, m.to_string()).unwrap();
        snapshot::read(&json_path)
    };
    // A version-2 file whose checksum was removed: edited, refused.
    let e = rewrite(&|m| {
        m.as_object_mut().unwrap().remove("checksum");
    });
    assert!(matches!(e, Err(SnapshotError::Checksum(_))), "{e:?}");
    // Files from before the checksum (version 1) still read.
    let old = rewrite(&|m| {
        m.as_object_mut().unwrap().remove("checksum");
        m["version"] = json!(1);
    });
    assert!(old.is_ok(), "{old:?}");
    // The data must lie beside the metadata.
    for data in ["../snap.bin", "/dev/zero"] {
        let e = rewrite(&|m| m["data"] = json!(data));
        assert!(
            matches!(e, Err(SnapshotError::NotASnapshot(_))),
            "{data}: {e:?}"
        );
    }
    let newer = rewrite(&|m| m["version"] = json!(99));
    assert!(
        matches!(newer, Err(SnapshotError::Newer { .. })),
        "{newer:?}"
    );
}
