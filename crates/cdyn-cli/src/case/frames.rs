//! The positions `q` of a run at some of its samples, for the viewer's
//! animation: at most a fixed number of frames however long the run, so
//! that a page stays small. When the frames run out, every other one is
//! dropped and later samples are taken half as often; the last sample
//! (the end state) is always kept.

/// Most frames kept, and most numbers (`frames × coordinates`, 8 MB) kept.
const MAX_FRAMES: usize = 2000;
const MAX_NUMBERS: usize = 1_000_000;

/// Positions at evenly spaced samples of a run (every `stride`-th one).
#[derive(Debug, Clone, Default)]
pub struct Frames {
    /// A run in joint coordinates: its frames are the bodies' poses at its `q`.
    poses: Option<cdyn::spatial::BodyPoses>,
    /// Times of the frames.
    pub t: Vec<f64>,
    /// Positions, `n` per frame, frame after frame.
    pub q: Vec<f64>,
    /// Coordinates per frame.
    pub n: usize,
    /// A frame is kept of every this many samples.
    pub stride: u64,
    /// Samples offered so far.
    pub samples: u64,
    /// Most frames kept; 0 when no frames are wanted.
    limit: usize,
}

impl Frames {
    /// No frames: [`Frames::push`] does nothing.
    pub fn none() -> Self {
        Frames::default()
    }

    /// Frames of a system with `n` coordinates.
    pub fn of(n: usize) -> Self {
        let limit = MAX_FRAMES.min((MAX_NUMBERS / n.max(1)).max(2));
        Frames { n, stride: 1, limit, ..Frames::default() }
    }

    /// Frames of a spatial run in joint coordinates: the bodies' poses at each `q`.
    pub fn of_poses(poses: cdyn::spatial::BodyPoses) -> Self {
        Frames { poses: Some(poses.clone()), ..Frames::of(poses.len()) }
    }

    /// Keeps the positions at `q` (the bodies' poses where the run is in joint coordinates).
    fn keep(&mut self, q: &[f64]) {
        match &mut self.poses {
            Some(poses) => {
                let start = self.q.len();
                self.q.resize(start + self.n, 0.0);
                poses.at(q, &mut self.q[start..]);
            }
            None => self.q.extend_from_slice(&q[..self.n]),
        }
    }

    /// Frames kept.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether none are kept (also when none are wanted).
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// The positions of frame `i`.
    pub fn q(&self, i: usize) -> &[f64] {
        &self.q[i * self.n..(i + 1) * self.n]
    }

    /// Offers the sample `(t, q)`.
    pub fn push(&mut self, t: f64, q: &[f64]) {
        if self.limit == 0 {
            return;
        }
        let at = self.samples;
        self.samples += 1;
        if !at.is_multiple_of(self.stride) {
            return;
        }
        if self.t.len() >= self.limit {
            self.halve();
            if !at.is_multiple_of(self.stride) {
                return;
            }
        }
        self.t.push(t);
        self.keep(q);
    }

    /// Keeps the end state `(t, q)` as the last frame, if it is not already.
    pub fn end(&mut self, t: f64, q: &[f64]) {
        if self.limit > 0 && self.t.last() != Some(&t) {
            self.t.push(t);
            self.keep(q);
        }
    }

    /// Drops every other frame (the odd ones) and doubles the stride.
    fn halve(&mut self) {
        let n = self.n;
        let kept = self.t.len().div_ceil(2);
        for i in 0..kept {
            self.t[i] = self.t[2 * i];
            self.q.copy_within(2 * i * n..(2 * i + 1) * n, i * n);
        }
        self.t.truncate(kept);
        self.q.truncate(kept * n);
        self.stride *= 2;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_runs_keep_evenly_spaced_frames_and_the_end() {
        let mut f = Frames::of(2);
        let samples = 5 * MAX_FRAMES as u64 + 3;
        for k in 0..samples {
            f.push(k as f64, &[k as f64, -(k as f64)]);
        }
        f.end((samples - 1) as f64, &[(samples - 1) as f64, 0.0]);
        assert!(f.len() <= MAX_FRAMES + 1 && f.len() > MAX_FRAMES / 4, "{}", f.len());
        assert_eq!(f.stride, 8);
        for i in 0..f.len() - 1 {
            assert_eq!(f.t[i], (i as u64 * f.stride) as f64);
            assert_eq!(f.q(i), [f.t[i], -f.t[i]]);
        }
        assert_eq!(*f.t.last().unwrap(), (samples - 1) as f64);
    }

    #[test]
    fn large_systems_keep_fewer_frames() {
        assert_eq!(Frames::of(9).limit, MAX_FRAMES);
        assert_eq!(Frames::of(10_000).limit, 100);
    }

    #[test]
    fn none_keeps_nothing() {
        let mut f = Frames::none();
        f.push(0.0, &[1.0]);
        f.end(1.0, &[1.0]);
        assert!(f.is_empty());
    }
}
