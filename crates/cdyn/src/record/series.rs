//! Sampled time histories for figures, of a size that does not grow with
//! the length of the run.

/// Most buckets a [`Series`] keeps: about three per pixel of a 1200-pixel-wide figure.
pub const SERIES_BUCKETS: usize = 4096;

/// Sampled time histories, for figures, of a size that does not grow with
/// the length of the run.
///
/// Up to [`SERIES_BUCKETS`] samples are kept as they are (one entry each).
/// Beyond that, consecutive samples are gathered into at most that many
/// buckets of equal count (the count doubles whenever the buckets run out),
/// and a bucket of more than one sample keeps two entries: at its first and
/// its last time, the smallest and largest value of each quantity, in the
/// order they occurred. A spike therefore stays in the figure however long
/// the run; only its position within its bucket (less than a pixel) is lost.
/// The statistics of a [`Record`](super::Record) are kept exactly, from every sample.
///
/// The four vectors hold the entries of the complete buckets; a partly
/// filled last bucket joins them when the recording ends.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Series {
    /// Times.
    pub t: Vec<f64>,
    /// The constraint value of largest magnitude, with its sign.
    pub phi: Vec<f64>,
    /// The energy constraint `Ψ`.
    pub psi: Vec<f64>,
    /// Error of the first observable against the reference; empty without one.
    pub error: Vec<f64>,
    /// The complete buckets, the vectors' source when buckets merge.
    buckets: Vec<Bucket>,
    /// The bucket being filled.
    open: Option<Bucket>,
    /// Samples per bucket (a power of two).
    width: u64,
    /// Samples taken so far, which orders the extremes within a bucket.
    samples: u64,
    /// Whether any sample had an error (then every entry has one, NaN where missing).
    has_error: bool,
}

/// The smallest and largest value of one quantity over a bucket, with the
/// sample index of each (to draw them in the order they occurred).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Extent {
    min: f64,
    min_at: u64,
    max: f64,
    max_at: u64,
}

impl Extent {
    /// The extent of no value yet.
    const EMPTY: Extent = Extent { min: f64::NAN, min_at: 0, max: f64::NAN, max_at: 0 };

    /// Takes in `v`, sample `at`; NaN only where nothing else is.
    fn add(&mut self, v: f64, at: u64) {
        if v < self.min || self.min.is_nan() {
            (self.min, self.min_at) = (v, at);
        }
        if v > self.max || self.max.is_nan() {
            (self.max, self.max_at) = (v, at);
        }
    }

    /// The extent of `self` followed by `later`.
    fn merge(self, later: Extent) -> Extent {
        let mut e = self;
        e.add(later.min, later.min_at);
        e.add(later.max, later.max_at);
        e
    }

    /// The two values in the order they occurred.
    fn ordered(&self) -> [f64; 2] {
        if self.max_at < self.min_at { [self.max, self.min] } else { [self.min, self.max] }
    }
}

/// Consecutive samples gathered: their first and last time and the extent of each quantity.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Bucket {
    count: u64,
    t: [f64; 2],
    /// Φ, Ψ and the error.
    values: [Extent; 3],
}

impl Bucket {
    /// `later` appended to `self`.
    fn merge(self, later: Bucket) -> Bucket {
        Bucket {
            count: self.count + later.count,
            t: [self.t[0], later.t[1]],
            values: [0, 1, 2].map(|i| self.values[i].merge(later.values[i])),
        }
    }
}

impl Series {
    /// An empty series.
    pub const fn new() -> Self {
        Series {
            t: Vec::new(),
            phi: Vec::new(),
            psi: Vec::new(),
            error: Vec::new(),
            buckets: Vec::new(),
            open: None,
            width: 1,
            samples: 0,
            has_error: false,
        }
    }

    /// Takes in one sample.
    pub fn push(&mut self, t: f64, phi: f64, psi: f64, error: Option<f64>) {
        let at = self.samples;
        self.samples += 1;
        self.has_error |= error.is_some();
        let width = self.width.max(1);
        let bucket = self.open.get_or_insert(Bucket { count: 0, t: [t, t], values: [Extent::EMPTY; 3] });
        bucket.count += 1;
        bucket.t[1] = t;
        for (extent, v) in bucket.values.iter_mut().zip([Some(phi), Some(psi), error]) {
            if let Some(v) = v {
                extent.add(v, at);
            }
        }
        if bucket.count >= width {
            let bucket = *bucket;
            self.open = None;
            self.close(bucket);
        }
    }

    /// Samples taken in.
    pub fn samples(&self) -> u64 {
        self.samples
    }

    /// Adds a complete bucket; when the buckets run out, merges them in pairs.
    fn close(&mut self, bucket: Bucket) {
        self.buckets.push(bucket);
        self.emit(bucket);
        if self.buckets.len() >= SERIES_BUCKETS {
            let merged: Vec<Bucket> =
                self.buckets.chunks(2).map(|p| p.iter().copied().reduce(Bucket::merge).unwrap_or(p[0])).collect();
            self.width = self.width.max(1) * 2;
            self.buckets.clear();
            for v in [&mut self.t, &mut self.phi, &mut self.psi, &mut self.error] {
                v.clear();
            }
            for b in merged {
                self.buckets.push(b);
                self.emit(b);
            }
        }
    }

    /// Appends the entries of `bucket` to the vectors.
    fn emit(&mut self, b: Bucket) {
        let n = if b.count > 1 { 2 } else { 1 };
        self.t.extend(&b.t[..n]);
        self.phi.extend(&b.values[0].ordered()[..n]);
        self.psi.extend(&b.values[1].ordered()[..n]);
        if self.has_error {
            // Entries from before the first error get none (NaN: not drawn).
            self.error.resize(self.t.len() - n, f64::NAN);
            self.error.extend(&b.values[2].ordered()[..n]);
        }
    }

    /// Ends the recording: the partly filled last bucket joins the vectors.
    pub fn finish(&mut self) {
        if let Some(b) = self.open.take() {
            self.buckets.push(b);
            self.emit(b);
        }
    }
}
