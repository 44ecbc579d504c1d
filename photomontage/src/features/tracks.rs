//! Tracks: pairwise keypoint matches joined across photos by union-find (Snavely, Seitz &
//! Szeliski, *Photo tourism*, SIGGRAPH 2006, §4.1: "matches … are organised into tracks, … a
//! track is inconsistent if it contains more than one keypoint in the same image", and such
//! tracks are dropped). Union-find with path halving and union by size (Tarjan 1975).
//!
//! Pure Rust: it needs no OpenCV and is tested with or without the `opencv` feature.
//!
//! # Known limitations
//! An inconsistent track is dropped whole; it is not split into consistent parts.

/// Verified matches between two photos, as pairs of keypoint indices (`a` in `photo_a`, `b` in
/// `photo_b`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PairMatches {
    pub photo_a: usize,
    pub photo_b: usize,
    pub matches: Vec<(usize, usize)>,
}

/// One keypoint of one photo.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct TrackNode {
    pub photo: usize,
    pub keypoint: usize,
}

/// The tracks found, and how many candidates were dropped.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TrackSet {
    /// Each track lists its keypoints ordered by photo; every photo appears at most once.
    pub tracks: Vec<Vec<TrackNode>>,
    /// Connected components with two keypoints in one photo (dropped).
    pub conflicts_dropped: usize,
}

/// Disjoint sets over `0..n` (union by size, path halving).
struct UnionFind {
    parent: Vec<usize>,
    size: Vec<usize>,
}

impl UnionFind {
    fn new(n: usize) -> Self {
        Self {
            parent: (0..n).collect(),
            size: vec![1; n],
        }
    }

    fn find(&mut self, mut x: usize) -> usize {
        while self.parent[x] != x {
            self.parent[x] = self.parent[self.parent[x]];
            x = self.parent[x];
        }
        x
    }

    fn union(&mut self, a: usize, b: usize) {
        let (mut ra, mut rb) = (self.find(a), self.find(b));
        if ra == rb {
            return;
        }
        if self.size[ra] < self.size[rb] {
            std::mem::swap(&mut ra, &mut rb);
        }
        self.parent[rb] = ra;
        self.size[ra] += self.size[rb];
    }
}

/// Why the input of [`build_tracks`] is unusable.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TrackError {
    #[error(
        "match ({photo}, keypoint {keypoint}) refers past the {count} keypoints of photo {photo}"
    )]
    KeypointOutOfRange {
        photo: usize,
        keypoint: usize,
        count: usize,
    },
    #[error("matches name photo {photo} but only {photos} photos were given")]
    PhotoOutOfRange { photo: usize, photos: usize },
}

/// Joins pairwise matches into tracks. `keypoint_counts[p]` is the number of keypoints of
/// photo `p`. Tracks are returned in a deterministic order (by their first keypoint).
///
/// # Errors
/// [`TrackError`] when a match names a photo or keypoint that does not exist.
pub fn build_tracks(
    keypoint_counts: &[usize],
    pairs: &[PairMatches],
) -> Result<TrackSet, TrackError> {
    let mut offsets = Vec::with_capacity(keypoint_counts.len() + 1);
    let mut total = 0;
    for &c in keypoint_counts {
        offsets.push(total);
        total += c;
    }
    offsets.push(total);
    let node = |photo: usize, keypoint: usize| -> Result<usize, TrackError> {
        let count = *keypoint_counts
            .get(photo)
            .ok_or(TrackError::PhotoOutOfRange {
                photo,
                photos: keypoint_counts.len(),
            })?;
        if keypoint >= count {
            return Err(TrackError::KeypointOutOfRange {
                photo,
                keypoint,
                count,
            });
        }
        Ok(offsets[photo] + keypoint)
    };
    let mut sets = UnionFind::new(total);
    let mut touched = vec![false; total];
    for pair in pairs {
        for &(a, b) in &pair.matches {
            let (na, nb) = (node(pair.photo_a, a)?, node(pair.photo_b, b)?);
            touched[na] = true;
            touched[nb] = true;
            sets.union(na, nb);
        }
    }
    // Group the touched nodes by root, in node order (deterministic).
    let mut by_root: std::collections::BTreeMap<usize, Vec<TrackNode>> =
        std::collections::BTreeMap::new();
    let mut first_of_root: std::collections::HashMap<usize, usize> =
        std::collections::HashMap::new();
    for n in (0..total).filter(|&n| touched[n]) {
        let root = sets.find(n);
        let key = *first_of_root.entry(root).or_insert(n);
        // offsets is ascending; the photo is the last offset ≤ n.
        let photo = offsets.partition_point(|&o| o <= n) - 1;
        by_root.entry(key).or_default().push(TrackNode {
            photo,
            keypoint: n - offsets[photo],
        });
    }
    let mut tracks = Vec::new();
    let mut conflicts_dropped = 0;
    for (_, mut nodes) in by_root {
        nodes.sort();
        let conflict = nodes.windows(2).any(|w| w[0].photo == w[1].photo);
        if conflict {
            conflicts_dropped += 1;
        } else if nodes.len() >= 2 {
            tracks.push(nodes);
        }
    }
    Ok(TrackSet {
        tracks,
        conflicts_dropped,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn n(photo: usize, keypoint: usize) -> TrackNode {
        TrackNode { photo, keypoint }
    }

    #[test]
    fn chains_join_across_photos_and_conflicts_are_dropped() {
        // Photo 0 kp 1 ↔ photo 1 kp 2 ↔ photo 2 kp 0: one track over three photos.
        // Photo 0 kp 3 ↔ photo 1 kp 0, photo 1 kp 0 ↔ photo 2 kp 4, photo 2 kp 4 ↔ photo 0 kp 2:
        // two keypoints of photo 0 in one component, dropped.
        // Photo 1 kp 5 ↔ photo 2 kp 5: a two-photo track.
        let pairs = [
            PairMatches {
                photo_a: 0,
                photo_b: 1,
                matches: vec![(1, 2), (3, 0)],
            },
            PairMatches {
                photo_a: 1,
                photo_b: 2,
                matches: vec![(2, 0), (0, 4), (5, 5)],
            },
            PairMatches {
                photo_a: 2,
                photo_b: 0,
                matches: vec![(4, 2)],
            },
        ];
        let set = build_tracks(&[4, 6, 6], &pairs).expect("valid");
        assert_eq!(set.conflicts_dropped, 1);
        assert_eq!(
            set.tracks,
            vec![vec![n(0, 1), n(1, 2), n(2, 0)], vec![n(1, 5), n(2, 5)]]
        );
    }

    #[test]
    fn a_match_past_the_keypoints_is_named() {
        let pairs = [PairMatches {
            photo_a: 0,
            photo_b: 1,
            matches: vec![(0, 7)],
        }];
        assert_eq!(
            build_tracks(&[2, 3], &pairs),
            Err(TrackError::KeypointOutOfRange {
                photo: 1,
                keypoint: 7,
                count: 3
            })
        );
        let pairs = [PairMatches {
            photo_a: 0,
            photo_b: 4,
            matches: vec![(0, 0)],
        }];
        assert_eq!(
            build_tracks(&[2, 3], &pairs),
            Err(TrackError::PhotoOutOfRange {
                photo: 4,
                photos: 2
            })
        );
    }

    #[test]
    fn a_long_chain_is_one_track() {
        // Keypoint 0 of each of 50 photos matched to the next: one 50-photo track.
        let pairs: Vec<PairMatches> = (0..49)
            .map(|p| PairMatches {
                photo_a: p,
                photo_b: p + 1,
                matches: vec![(0, 0)],
            })
            .collect();
        let set = build_tracks(&[1; 50], &pairs).expect("valid");
        assert_eq!(set.tracks.len(), 1);
        assert_eq!(set.tracks[0].len(), 50);
        assert_eq!(set.conflicts_dropped, 0);
    }
}
