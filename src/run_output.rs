//! A run's files written as it goes: each row of `trajectory.csv` (and
//! its shape in `shape.csv`) the moment the run hands it over
//! (`runtime::RowSink`), so that a run of any length holds a bounded
//! number of rows in memory and even a killed run leaves on disk the rows
//! it computed. Beside the files it keeps what the figures and the summary
//! need: the tip at the compared times (as many as the measured record),
//! the plotted paths thinned to a bounded number of points, and the last
//! row.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use runtime::{Dynamics, RowSink};

use crate::backend::Loaded;
use crate::run::{ArmTips, Table};
use crate::shape::Shape;

/// Most points a figure keeps: far more than its pixels across.
pub const MAX_PLOTTED: usize = 20_000;

/// A point of a plotted path: t, x, y.
pub type PathPoint = (f64, f64, f64);

/// What a run's figures and summary read, kept as its rows went by.
#[derive(Default)]
pub struct Kept {
    /// Rows written to trajectory.csv.
    pub rows: usize,
    /// The last row's time and state.
    pub last: Option<(f64, Vec<f64>)>,
    /// The tip (x, y, z) at every row, when the rows are a measured
    /// record's times (`[compare]`); else empty.
    pub tips: Vec<(f64, [f64; 3])>,
    /// Each free body's path (t, x, y), by name.
    pub paths: Vec<(String, Thinned<PathPoint>)>,
    /// The tip (x, y, z) over the run, thinned, for its plot.
    pub tip: Thinned<(f64, [f64; 3])>,
    /// With contact: the tip's path (t, x, y) and the contact columns.
    pub tip_path: Thinned<PathPoint>,
    pub forces: Thinned<(f64, Vec<f64>)>,
}

/// The writer behind a run's `RowSink`.
struct Writer {
    trajectory: BufWriter<File>,
    shape: Option<(Shape, BufWriter<File>)>,
    joints: bool,
    /// Each arm's tip, for a model of several arms.
    tips: Option<ArmTips>,
    compare: bool,
    /// Free bodies: name and the index of x in the state.
    bodies: Vec<(String, usize)>,
    kept: Kept,
    /// The first write that failed: the run goes on, the files stop.
    error: Option<std::io::Error>,
    /// When the files were last flushed: at least every second, so that
    /// a killed run leaves its rows up to then on disk.
    flushed: Instant,
}

/// Longest a written row waits in a buffer.
const FLUSH_EVERY: Duration = Duration::from_secs(1);

/// A run's output files, open for its rows.
pub struct RunOutput {
    writer: Arc<Mutex<Writer>>,
}

/// Files past this size are announced before the run.
pub const LARGE_BYTES: f64 = 1e9;

/// What a run of `rows` rows from x0 will write (bytes of trajectory.csv
/// and of shape.csv), from its first row written out; a line to say
/// before the run when that is over [`LARGE_BYTES`].
pub fn size_warning(
    loaded: &Loaded,
    x0: &[f64],
    shape: Option<&Shape>,
    rows: f64,
) -> Option<String> {
    let arm = &*loaded.arm;
    let n = arm.dof();
    let out = arm.outputs(0.0, &x0[..n], &x0[n..2 * n]);
    let contact = crate::contact::column_names(arm).len();
    let joints = !arm.info().constraints.is_empty();
    let tips = ArmTips::of(loaded).map_or(Vec::new(), |a| a.at(arm, 0.0, &x0[..n]));
    let row = Table::row(arm, 0.0, x0, &out, joints, &vec![0.0; contact], &tips);
    let mut buf = Vec::new();
    Table::write_row(&mut buf, &row).ok()?;
    let trajectory = rows * buf.len() as f64;
    buf.clear();
    if let Some(s) = shape {
        s.write_rows(arm, 0.0, &x0[..n], &mut buf).ok()?;
    }
    let shape_bytes = rows * buf.len() as f64;
    let gb = |b: f64| b / 1e9;
    (trajectory + shape_bytes > LARGE_BYTES).then(|| {
        format!(
            "this run writes {rows:.0} rows, about {:.1} GB (trajectory.csv {:.1} GB, shape.csv {:.1} GB): a longer --output-dt, or --shape-points 0, writes less",
            gb(trajectory + shape_bytes),
            gb(trajectory),
            gb(shape_bytes)
        )
    })
}

impl RunOutput {
    /// Open `trajectory` (and `shape` with its path) and write their
    /// headers; `compare`: keep the tip at every row.
    pub fn create(
        loaded: &Loaded,
        trajectory: &Path,
        shape: Option<(Shape, std::path::PathBuf)>,
        compare: bool,
    ) -> Result<Self> {
        let arm = &*loaded.arm;
        let open = |p: &Path| -> Result<BufWriter<File>> {
            let f = File::create(p).with_context(|| format!("cannot write {}", p.display()))?;
            Ok(BufWriter::new(f))
        };
        let mut t = open(trajectory)?;
        let tips = ArmTips::of(loaded);
        writeln!(t, "{}", Table::names(arm, tips.as_ref()).join(","))?;
        let shape = match shape {
            Some((s, p)) => {
                let mut w = open(&p)?;
                Shape::write_header(&mut w)?;
                Some((s, w))
            }
            None => None,
        };
        let names: Vec<String> = loaded.model.bodies.iter().map(|b| b.name.clone()).collect();
        let bodies = crate::joints::free_bodies(arm, &names);
        let kept = Kept {
            paths: (bodies.iter())
                .map(|(b, _)| (b.clone(), Thinned::default()))
                .collect(),
            ..Default::default()
        };
        Ok(Self {
            writer: Arc::new(Mutex::new(Writer {
                trajectory: t,
                shape,
                joints: !arm.info().constraints.is_empty(),
                tips,
                compare,
                bodies,
                kept,
                error: None,
                flushed: Instant::now(),
            })),
        })
    }

    /// The sink a run hands its rows to.
    pub fn sink(&self) -> RowSink {
        let writer = self.writer.clone();
        RowSink::new(move |arm, row| {
            let mut w = writer.lock().unwrap_or_else(|e| e.into_inner());
            w.row(arm, row);
        })
    }

    /// Flush the files; what the run's figures and summary read. An error
    /// if a write failed (the run's rows up to it are on disk).
    pub fn finish(self) -> Result<Kept> {
        let mut w = self.writer.lock().unwrap_or_else(|e| e.into_inner());
        if w.error.is_none() {
            w.error = w.flush().err();
        }
        if let Some(e) = w.error.take() {
            return Err(anyhow::anyhow!("cannot write the run's files: {e}"));
        }
        Ok(std::mem::take(&mut w.kept))
    }
}

impl Writer {
    fn flush(&mut self) -> std::io::Result<()> {
        self.trajectory.flush()?;
        match &mut self.shape {
            Some((_, s)) => s.flush(),
            None => Ok(()),
        }
    }

    fn row(&mut self, arm: &dyn Dynamics, row: &runtime::Row<'_>) {
        let n = arm.dof();
        let (t, x) = (row.t, row.x);
        let out = arm.outputs(t, &x[..n], &x[n..2 * n]);
        if self.error.is_none() {
            let tips = (self.tips.as_ref()).map_or(Vec::new(), |a| a.at(arm, t, &x[..n]));
            let values = Table::row(arm, t, x, &out, self.joints, row.contact, &tips);
            let written = Table::write_row(&mut self.trajectory, &values).and_then(|_| {
                match &mut self.shape {
                    Some((s, w)) => s.write_rows(arm, t, &x[..n], w),
                    None => Ok(()),
                }
            });
            self.error = written.err();
            if self.error.is_none() && self.flushed.elapsed() > FLUSH_EVERY {
                self.error = self.flush().err();
                self.flushed = Instant::now();
            }
        }
        let k = &mut self.kept;
        k.rows += 1;
        k.last = Some((t, x.to_vec()));
        if self.compare {
            k.tips.push((t, [out[0], out[1], out[2]]));
        }
        k.tip.push((t, [out[0], out[1], out[2]]));
        for ((_, ix), (_, path)) in self.bodies.iter().zip(&mut k.paths) {
            path.push((t, x[*ix], x[ix + 1]));
        }
        if arm.contact().is_some() {
            k.tip_path.push((t, out[0], out[1]));
            k.forces.push((t, row.contact.to_vec()));
        }
    }
}

/// A figure's points from a run of any length: every k-th row, k doubling
/// whenever more than [`MAX_PLOTTED`] are held, and always the last.
pub struct Thinned<T> {
    every: usize,
    seen: usize,
    points: Vec<T>,
    last: Option<T>,
}

impl<T> Default for Thinned<T> {
    fn default() -> Self {
        Self {
            every: 1,
            seen: 0,
            points: Vec::new(),
            last: None,
        }
    }
}

impl<T: Clone> Thinned<T> {
    pub fn push(&mut self, p: T) {
        if self.seen.is_multiple_of(self.every) {
            self.points.push(p.clone());
            if self.points.len() > MAX_PLOTTED {
                let mut k = 0;
                self.points.retain(|_| {
                    k += 1;
                    k % 2 == 1
                });
                self.every *= 2;
            }
        }
        self.seen += 1;
        self.last = Some(p);
    }

    /// The points kept, ending with the last pushed.
    pub fn points(&self) -> Vec<T> {
        let mut v = self.points.clone();
        // The last row, unless it is the last point kept.
        if let Some(l) = &self.last
            && !(self.seen - 1).is_multiple_of(self.every)
        {
            v.push(l.clone());
        }
        v
    }

    pub fn is_empty(&self) -> bool {
        self.seen == 0
    }
}
