//! PCD (Point Cloud Library) files: an organized writer and a reader for PCD v0.7 files.
//!
//! The writer stores the whole grid (`WIDTH` = columns, `HEIGHT` = rows x planes, NaN x y z where
//! there is no return), so `POINTS` always equals `WIDTH * HEIGHT` and the data. Fields, in order:
//! `x y z` (F4, vehicle frame, metres), `intensity` (F4, `[0, 1]`), `ring` (U2), `time` (F8,
//! seconds), `label` (U4: the SemanticKITTI class, U4 as PCL's `PointXYZL` expects), `instance`
//! (U4), `ground` (U1, 0/1), `range` (F4, metres), `sensor` (U1), `echo` (U1), `column` (U4) and
//! `normal_x normal_y normal_z` (F4). A comment line `# groundtruth rows=R planes=P` lets our
//! reader restore multi-echo grids; other tools ignore it.
//!
//! The reader accepts `ascii`, `binary` and `binary_compressed` (LZF, field-major) data,
//! any field order, types F/I/U of sizes 1/2/4/8 and COUNT > 1 (only the first element is read).
//! Organized files (`HEIGHT > 1`) become a `HEIGHT x WIDTH` grid, unorganized ones a `1 x N` grid.
//! Fields the file lacks get defaults: ring = row, column = column, sensor 0, time 0, label 0,
//! instance 0, ground = whether the label is a ground class, range = distance from the origin.
//! The ROS drivers' conventions are followed: cells at exactly (0, 0, 0) are no-returns (ouster-ros
//! and older velodyne drivers keep them so), an integer `range` field is millimetres (ouster-ros'
//! uint32), an integer time field (`t`, `time`, `timestamp`) is nanoseconds (ouster-ros' uint32
//! `t`), float times are seconds. Rows stay in the file's order; [`PcdInfo`] says whether the file
//! has a `ring` field and our grid line, for `classifier::ordering` to put the rows in elevation
//! order.
//!
//! [`PcdFrame`] parses a file without decoding it, so that single points can be looked at first
//! and the whole file then decoded with its rows where the caller wants them and its points moved
//! into the vehicle frame, in one pass (to put a driver's rows in elevation order as they are
//! decoded, for instance).
//!
//! The writer writes our layout ([`encode`], rows bottom-first) or a ROS driver's
//! ([`encode_layout`], [`PcdLayout`]).

mod decode;
mod header;
mod layouts;
mod reader;
mod writer;

pub(crate) use header::{DataKind, FieldDecl, grid_of_comment, layout};
pub use layouts::{PcdLayout, encode_layout, write_layout};
pub use reader::{PcdFrame, PcdInfo, read, read_bytes, read_bytes_into, read_bytes_with_info, read_with_info};
pub use writer::{RECORD_BYTES, encode, write};
