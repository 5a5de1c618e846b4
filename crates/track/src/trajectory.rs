//! The trajectory row: one frame of a track in pixels and in the local frame, as `trajectories/<clip>.csv`,
//! `bouncelab track` and the store's `trajectory` table hold it (`docs/outputs.md`).
//!
//! The row is the tracker's [`BallFix`] plus the two local-frame coordinates, so each field is declared once.
//! Its serde form is written by hand because the `csv` crate cannot write a `#[serde(flatten)]` struct
//! (it would need a map): [`TrajectoryRow::cells`] is the one place that lists the columns' values in order.

use std::fmt;

use crate::tracker::{BallFix, Status};
use serde::de::{self, IgnoredAny, MapAccess, SeqAccess, Visitor};
use serde::ser::SerializeStruct;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// The columns of a trajectory, in order: the header of `trajectories/<clip>.csv` and of `bouncelab track`'s
/// output, and the store's `trajectory` table after its `shot_id`. Each name is a field of [`BallFix`] or
/// of [`TrajectoryRow`].
pub const TRAJECTORY_COLUMNS: [&str; 10] = [
    "frame", "t_s", "x_px", "y_px", "r_px", "sigma_px", "quality", "status", "x_m", "y_m",
];

/// Position of `status` in [`TRAJECTORY_COLUMNS`]; `frame` is at 0 and every other column is a number.
const STATUS_COLUMN: usize = 7;

/// One frame of a trajectory in pixels and in the local frame (the `trajectories/<clip>.csv` row).
///
/// The fix's `sigma_r_px` is not a column: a row read from a file or from the store has it NaN, and two rows
/// are equal when their columns are ([`TrajectoryRow::cells`]).
#[derive(Debug, Clone, Copy)]
pub struct TrajectoryRow {
    /// The ball in the image, as the tracker measured it.
    pub fix: BallFix,
    /// Along the surface, down-slope, m (origin at the contact column); NaN when not measured or without
    /// a local frame.
    pub x_m: f64,
    /// Above the surface line, m; NaN when not measured or without a local frame.
    pub y_m: f64,
}

/// One cell of a [`TrajectoryRow`], under its column of [`TRAJECTORY_COLUMNS`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TrajectoryCell {
    /// The frame index.
    Frame(usize),
    /// A number in the unit its column name gives (NaN when not measured).
    Number(f64),
    /// The tracker's status (written as [`Status::name`]).
    Status(Status),
}

impl TrajectoryRow {
    /// The row's cells in the order of [`TRAJECTORY_COLUMNS`]: what every writer of a trajectory writes, each
    /// with its own spelling of a number.
    pub fn cells(&self) -> [TrajectoryCell; 10] {
        use TrajectoryCell::{Frame, Number};
        let f = &self.fix;
        [
            Frame(f.frame),
            Number(f.t_s),
            Number(f.x_px),
            Number(f.y_px),
            Number(f.r_px),
            Number(f.sigma_px),
            Number(f.quality),
            TrajectoryCell::Status(f.status),
            Number(self.x_m),
            Number(self.y_m),
        ]
    }

    /// The row whose [`TrajectoryRow::cells`] are `cells` (the fix's `sigma_r_px`, not a column, NaN); `None`
    /// if a cell is not of its column's kind.
    pub fn from_cells(cells: [TrajectoryCell; 10]) -> Option<TrajectoryRow> {
        let (mut frame, mut status, mut numbers, mut n) = (None, None, [0.0; 8], 0);
        for (column, cell) in cells.into_iter().enumerate() {
            match (column, cell) {
                (0, TrajectoryCell::Frame(f)) => frame = Some(f),
                (STATUS_COLUMN, TrajectoryCell::Status(s)) => status = Some(s),
                (c, TrajectoryCell::Number(x)) if c != 0 && c != STATUS_COLUMN => {
                    numbers[n] = x;
                    n += 1;
                }
                _ => return None,
            }
        }
        Some(TrajectoryRow::from_columns(frame?, numbers, status?))
    }

    /// The row of `frame`, `numbers` (the columns other than `frame` and `status`, in their order) and
    /// `status`.
    fn from_columns(frame: usize, numbers: [f64; 8], status: Status) -> TrajectoryRow {
        let [t_s, x_px, y_px, r_px, sigma_px, quality, x_m, y_m] = numbers;
        TrajectoryRow {
            fix: BallFix {
                frame,
                t_s,
                x_px,
                y_px,
                r_px,
                sigma_px,
                sigma_r_px: f64::NAN,
                quality,
                status,
            },
            x_m,
            y_m,
        }
    }
}

impl PartialEq for TrajectoryRow {
    fn eq(&self, other: &Self) -> bool {
        self.cells() == other.cells()
    }
}

impl Serialize for TrajectoryRow {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut s = serializer.serialize_struct("TrajectoryRow", TRAJECTORY_COLUMNS.len())?;
        for (name, cell) in TRAJECTORY_COLUMNS.into_iter().zip(self.cells()) {
            match cell {
                TrajectoryCell::Frame(v) => s.serialize_field(name, &v)?,
                TrajectoryCell::Number(v) => s.serialize_field(name, &v)?,
                TrajectoryCell::Status(v) => s.serialize_field(name, &v)?,
            }
        }
        s.end()
    }
}

impl<'de> Deserialize<'de> for TrajectoryRow {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_struct("TrajectoryRow", &TRAJECTORY_COLUMNS, RowVisitor)
    }
}

/// Reads a row as a map (named columns, in any order; others ignored) or as a sequence (the columns in order).
struct RowVisitor;

/// The cells read so far, by column.
#[derive(Default)]
struct Partial {
    frame: Option<usize>,
    status: Option<Status>,
    numbers: [Option<f64>; 10],
}

impl Partial {
    fn read<'de, A: CellSource<'de>>(&mut self, column: usize, source: &mut A) -> Result<(), A::Error> {
        let name = TRAJECTORY_COLUMNS[column];
        let duplicate = match column {
            0 => self.frame.replace(source.cell()?).is_some(),
            STATUS_COLUMN => self.status.replace(source.cell()?).is_some(),
            _ => self.numbers[column].replace(source.cell()?).is_some(),
        };
        if duplicate {
            return Err(de::Error::duplicate_field(name));
        }
        Ok(())
    }

    fn finish<E: de::Error>(self) -> Result<TrajectoryRow, E> {
        let missing = |column: usize| E::missing_field(TRAJECTORY_COLUMNS[column]);
        let frame = self.frame.ok_or_else(|| missing(0))?;
        let status = self.status.ok_or_else(|| missing(STATUS_COLUMN))?;
        let mut numbers = [0.0; 8];
        let columns = (0..TRAJECTORY_COLUMNS.len()).filter(|&c| c != 0 && c != STATUS_COLUMN);
        for (slot, column) in numbers.iter_mut().zip(columns) {
            *slot = self.numbers[column].ok_or_else(|| missing(column))?;
        }
        Ok(TrajectoryRow::from_columns(frame, numbers, status))
    }
}

/// Where the next cell's value comes from (a map's value or a sequence's element).
trait CellSource<'de> {
    type Error: de::Error;
    fn cell<T: Deserialize<'de>>(&mut self) -> Result<T, Self::Error>;
}

struct MapValues<A>(A);

impl<'de, A: MapAccess<'de>> CellSource<'de> for MapValues<A> {
    type Error = A::Error;
    fn cell<T: Deserialize<'de>>(&mut self) -> Result<T, A::Error> {
        self.0.next_value()
    }
}

struct SeqValues<A>(A, usize);

impl<'de, A: SeqAccess<'de>> CellSource<'de> for SeqValues<A> {
    type Error = A::Error;
    fn cell<T: Deserialize<'de>>(&mut self) -> Result<T, A::Error> {
        let value = self.0.next_element()?;
        value.ok_or_else(|| de::Error::invalid_length(self.1, &"the 10 trajectory columns"))
    }
}

impl<'de> Visitor<'de> for RowVisitor {
    type Value = TrajectoryRow;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "a trajectory row ({})", TRAJECTORY_COLUMNS.join(", "))
    }

    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<TrajectoryRow, A::Error> {
        let mut values = MapValues(map);
        let mut row = Partial::default();
        while let Some(key) = values.0.next_key::<String>()? {
            match TRAJECTORY_COLUMNS.iter().position(|c| *c == key) {
                Some(column) => row.read(column, &mut values)?,
                None => {
                    values.0.next_value::<IgnoredAny>()?;
                }
            }
        }
        row.finish()
    }

    fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<TrajectoryRow, A::Error> {
        let mut values = SeqValues(seq, 0);
        let mut row = Partial::default();
        for column in 0..TRAJECTORY_COLUMNS.len() {
            values.1 = column;
            row.read(column, &mut values)?;
        }
        row.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn row(status: Status) -> TrajectoryRow {
        TrajectoryRow {
            fix: BallFix {
                frame: 3,
                t_s: 0.5,
                x_px: 1.0,
                y_px: 2.0,
                r_px: 3.0,
                sigma_px: 0.1,
                sigma_r_px: 0.2,
                quality: 0.9,
                status,
            },
            x_m: 0.01,
            y_m: 0.02,
        }
    }

    #[test]
    fn the_serde_header_is_the_column_list_and_statuses_keep_their_names() {
        let mut w = csv::Writer::from_writer(Vec::new());
        for s in Status::ALL {
            w.serialize(row(s)).unwrap();
        }
        let text = String::from_utf8(w.into_inner().unwrap()).unwrap();
        let mut lines = text.lines();
        assert_eq!(lines.next().unwrap(), TRAJECTORY_COLUMNS.join(","));
        for (s, line) in Status::ALL.into_iter().zip(lines) {
            assert_eq!(line.split(',').nth(7), Some(s.name()), "{line}");
            assert_eq!(Status::from_name(s.name()), Ok(s));
        }
        assert_eq!(
            Status::from_name("lost").unwrap_err().to_string(),
            "unknown status `lost` (known: ok, occluded, cut_by_border, absent, ambiguous)"
        );
    }

    /// `bouncelab track`'s output is this serde form: the exact text a derived `Serialize` over the same
    /// fields wrote (numbers in the `csv` crate's spelling, NaN as `NaN`, the radius σ left out).
    #[test]
    fn a_row_is_written_as_the_derived_form_wrote_it() {
        let mut w = csv::Writer::from_writer(Vec::new());
        w.serialize(row(Status::Ok)).unwrap();
        let absent = TrajectoryRow {
            fix: BallFix::absent(4, 0.0004, Status::Absent),
            x_m: f64::NAN,
            y_m: f64::NAN,
        };
        w.serialize(absent).unwrap();
        let text = String::from_utf8(w.into_inner().unwrap()).unwrap();
        assert_eq!(
            text,
            "frame,t_s,x_px,y_px,r_px,sigma_px,quality,status,x_m,y_m\n\
             3,0.5,1.0,2.0,3.0,0.1,0.9,ok,0.01,0.02\n\
             4,0.0004,NaN,NaN,NaN,NaN,0.0,absent,NaN,NaN\n"
        );
    }

    /// The first row of a CSV text with a header.
    fn first_row(text: &str) -> Result<TrajectoryRow, String> {
        let mut r = csv::Reader::from_reader(text.as_bytes());
        r.deserialize().next().unwrap().map_err(|e| e.to_string())
    }

    #[test]
    fn a_row_is_read_by_column_name_in_any_order_and_a_missing_column_is_named() {
        let back = first_row(
            "y_m,x_m,status,quality,sigma_px,r_px,y_px,x_px,t_s,frame,note\n\
             0.02,0.01,occluded,0.9,0.1,3.0,2.0,1.0,0.5,3,ignored\n",
        )
        .unwrap();
        assert_eq!(back.cells(), row(Status::Occluded).cells());
        assert!(back.fix.sigma_r_px.is_nan(), "not a column, so not known");

        let e = first_row("frame,t_s,x_px,y_px,r_px,sigma_px,quality,status,x_m\n3,0.5,1,2,3,0.1,0.9,ok,0.01\n")
            .unwrap_err();
        assert!(e.contains("missing field `y_m`"), "{e}");

        let e = first_row("frame,t_s,x_px,y_px,r_px,sigma_px,quality,status,x_m,y_m\n3,0.5,1,2,3,0.1,0.9,lost,0,0\n")
            .unwrap_err();
        assert!(e.contains("lost"), "{e}");
    }

    #[test]
    fn rows_are_equal_when_their_columns_are_and_cells_invert() {
        let a = row(Status::Ok);
        let mut b = a;
        b.fix.sigma_r_px = f64::NAN;
        assert_eq!(a, b, "the radius σ is not a column");
        b.fix.quality = 0.8;
        assert_ne!(a, b);
        assert_eq!(TrajectoryRow::from_cells(a.cells()), Some(a));
        let mut swapped = a.cells();
        swapped.swap(0, 7);
        assert_eq!(
            TrajectoryRow::from_cells(swapped),
            None,
            "a cell of another column's kind"
        );
    }

    #[test]
    fn a_row_without_headers_is_read_in_column_order() {
        let text = "3,0.5,1.0,2.0,3.0,0.1,0.9,ok,0.01,0.02\n";
        let mut r = csv::ReaderBuilder::new()
            .has_headers(false)
            .from_reader(text.as_bytes());
        let back: TrajectoryRow = r.deserialize().next().unwrap().unwrap();
        assert_eq!(back.cells(), row(Status::Ok).cells());
        let mut r = csv::ReaderBuilder::new()
            .has_headers(false)
            .from_reader("3,0.5,1.0\n".as_bytes());
        assert!(r.deserialize::<TrajectoryRow>().next().unwrap().is_err());
    }

    fn finite() -> impl Strategy<Value = f64> {
        prop_oneof![any::<f64>().prop_filter("finite", |x| x.is_finite()), -1e4..1e4f64]
    }

    proptest! {
        /// Written and read back through the CSV form, every column survives (numbers bit for bit: the
        /// `csv` crate writes the shortest text that reads back to the same double).
        #[test]
        fn a_row_survives_its_csv_form(
            frame in 0..usize::MAX,
            v in proptest::collection::vec(finite(), 8),
            status in proptest::sample::select(Status::ALL.to_vec()),
        ) {
            let row = TrajectoryRow::from_columns(frame, [v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]], status);
            let mut w = csv::Writer::from_writer(Vec::new());
            w.serialize(row).unwrap();
            let text = w.into_inner().unwrap();
            let back: TrajectoryRow = csv::Reader::from_reader(&text[..]).deserialize().next().unwrap().unwrap();
            for (a, b) in back.cells().into_iter().zip(row.cells()) {
                match (a, b) {
                    (TrajectoryCell::Number(a), TrajectoryCell::Number(b)) => prop_assert_eq!(a.to_bits(), b.to_bits()),
                    (a, b) => prop_assert_eq!(a, b),
                }
            }
        }
    }
}
