//! What the readers need to know of each stream: its file, its columns, and how its
//! columnar form is built, appended to and cut.

use super::csvread::Columns;
use super::scan::{MAX_SLOTS, RowSink};
use crate::{ImuStream, TableStream};
use std::ops::Range;

/// One of the two CSV streams of a recording.
pub(crate) trait Stream: RowSink + Sized {
    /// File name in the recording folder.
    const FILE: &'static str;
    /// Required columns, `t` first (the readers find the time in slot 0).
    const REQUIRED: &'static [&'static str];
    /// The optional column, kept when the header has it.
    const OPTIONAL: &'static str;
    /// An empty stream with room for `rows`, with the optional column or without.
    fn with_capacity(optional: bool, rows: usize) -> Self;
    /// The exact reader's columns, in `REQUIRED` then `OPTIONAL` order.
    fn from_columns(c: Columns) -> Self;
    /// Appends another part (the rows after this one's).
    fn append(&mut self, other: Self);
    /// Keeps only the rows in `keep`.
    fn keep(&mut self, keep: Range<usize>);
    /// Time stamps, s.
    fn t(&self) -> &[f64];
}

/// `v[keep]`, in place.
fn cut(v: &mut Vec<f64>, keep: &Range<usize>) {
    v.truncate(keep.end);
    v.drain(..keep.start);
}

impl RowSink for ImuStream {
    #[inline]
    fn push(&mut self, r: &[f64; MAX_SLOTS]) {
        self.t.push(r[0]);
        for k in 0..3 {
            self.accel[k].push(r[1 + k]);
            self.gyro[k].push(r[4 + k]);
        }
        if let Some(tc) = &mut self.temp {
            tc.push(r[7]);
        }
    }
}

impl Stream for ImuStream {
    const FILE: &'static str = "imu.csv";
    const REQUIRED: &'static [&'static str] = &["t", "ax", "ay", "az", "gx", "gy", "gz"];
    const OPTIONAL: &'static str = "temp";

    fn with_capacity(temp: bool, rows: usize) -> Self {
        let col = || Vec::with_capacity(rows);
        ImuStream {
            t: col(),
            accel: [col(), col(), col()],
            gyro: [col(), col(), col()],
            temp: temp.then(col),
        }
    }

    fn from_columns(Columns { mut cols }: Columns) -> Self {
        let mut take = |k: usize| cols[k].take().expect("required column");
        ImuStream {
            t: take(0),
            accel: [take(1), take(2), take(3)],
            gyro: [take(4), take(5), take(6)],
            temp: cols[7].take(),
        }
    }

    fn append(&mut self, o: Self) {
        self.t.extend(o.t);
        for (a, b) in self
            .accel
            .iter_mut()
            .chain(&mut self.gyro)
            .zip(o.accel.into_iter().chain(o.gyro))
        {
            a.extend(b);
        }
        if let (Some(a), Some(b)) = (&mut self.temp, o.temp) {
            a.extend(b);
        }
    }

    fn keep(&mut self, keep: Range<usize>) {
        let cols = self.accel.iter_mut().chain(&mut self.gyro);
        for c in std::iter::once(&mut self.t)
            .chain(cols)
            .chain(&mut self.temp)
        {
            cut(c, &keep);
        }
    }

    fn t(&self) -> &[f64] {
        &self.t
    }
}

impl RowSink for TableStream {
    #[inline]
    fn push(&mut self, r: &[f64; MAX_SLOTS]) {
        self.t.push(r[0]);
        self.outer.push(r[1]);
        self.inner.push(r[2]);
        self.outer_rate.push(r[3]);
        self.inner_rate.push(r[4]);
        if let Some(a) = &mut self.ambient {
            a.push(r[5]);
        }
    }
}

impl Stream for TableStream {
    const FILE: &'static str = "table.csv";
    const REQUIRED: &'static [&'static str] = &["t", "outer", "inner", "outer_rate", "inner_rate"];
    const OPTIONAL: &'static str = "ambient";

    fn with_capacity(ambient: bool, rows: usize) -> Self {
        let col = || Vec::with_capacity(rows);
        TableStream {
            t: col(),
            outer: col(),
            inner: col(),
            outer_rate: col(),
            inner_rate: col(),
            ambient: ambient.then(col),
        }
    }

    fn from_columns(Columns { mut cols }: Columns) -> Self {
        let mut take = |k: usize| cols[k].take().expect("required column");
        TableStream {
            t: take(0),
            outer: take(1),
            inner: take(2),
            outer_rate: take(3),
            inner_rate: take(4),
            ambient: cols[5].take(),
        }
    }

    fn append(&mut self, o: Self) {
        self.t.extend(o.t);
        self.outer.extend(o.outer);
        self.inner.extend(o.inner);
        self.outer_rate.extend(o.outer_rate);
        self.inner_rate.extend(o.inner_rate);
        if let (Some(a), Some(b)) = (&mut self.ambient, o.ambient) {
            a.extend(b);
        }
    }

    fn keep(&mut self, keep: Range<usize>) {
        let cols = [
            &mut self.t,
            &mut self.outer,
            &mut self.inner,
            &mut self.outer_rate,
            &mut self.inner_rate,
        ];
        for c in cols.into_iter().chain(&mut self.ambient) {
            cut(c, &keep);
        }
    }

    fn t(&self) -> &[f64] {
        &self.t
    }
}
