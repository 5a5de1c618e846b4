//! The crate's one error type.

use std::path::PathBuf;

/// A `Result` whose error is [`StoreError`].
pub type Result<T, E = StoreError> = std::result::Result<T, E>;

/// Everything that can go wrong with the results store. Each variant names the database file (`:memory:` for
/// an in-memory store) and, where there is one, the table and field.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum StoreError {
    /// The database could not be opened, or its pragmas could not be set.
    #[error("{}: cannot open the results store: {source}", .path.display())]
    Open {
        /// The database file.
        path: PathBuf,
        /// What SQLite said.
        #[source]
        source: rusqlite::Error,
    },
    /// A statement on a table failed (constraint, I/O, busy, corrupt file …).
    #[error("{}: table `{table}`: {source}", .path.display())]
    Sql {
        /// The database file.
        path: PathBuf,
        /// The table the statement was about.
        table: &'static str,
        /// What SQLite said.
        #[source]
        source: rusqlite::Error,
    },
    /// The disk holding the database is full: the statement or transaction was rolled back, and what earlier
    /// transactions stored is kept.
    #[error(
        "{}: the disk is full, so the results store could not be written (table `{table}`); what was stored before is kept: free space and run again",
        .path.display()
    )]
    DiskFull {
        /// The database file.
        path: PathBuf,
        /// The table the statement was about (`(transaction)` for the commit).
        table: &'static str,
    },
    /// A value is not acceptable for its column, or a stored value cannot be read back.
    #[error("{}: table `{table}`, field `{field}`: {message}", .path.display())]
    Field {
        /// The database file.
        path: PathBuf,
        /// The table.
        table: &'static str,
        /// The column.
        field: &'static str,
        /// What is wrong.
        message: String,
    },
    /// A stored trajectory row has a status this build does not know (written by a newer or edited store):
    /// refused, never skipped.
    #[error("{}: table `trajectory`, shot {clip} (id {shot_id}), frame {frame}: {source}", .path.display())]
    UnknownStatus {
        /// The database file.
        path: PathBuf,
        /// The shot's clip name.
        clip: String,
        /// The shot's id.
        shot_id: i64,
        /// The row's frame index.
        frame: i64,
        /// The name found.
        #[source]
        source: bouncelab_track::UnknownStatus,
    },
    /// A row referred to by id does not exist.
    #[error("{}: table `{table}`: no row with id {id}", .path.display())]
    NotFound {
        /// The database file.
        path: PathBuf,
        /// The table.
        table: &'static str,
        /// The id asked for.
        id: i64,
    },
    /// The file was written by a newer bouncelab with a schema this build does not know.
    #[error(
        "{}: table `schema_version`: the store has schema version {found}, this program knows up to \
         {supported}; use a newer bouncelab",
        .path.display()
    )]
    SchemaTooNew {
        /// The database file.
        path: PathBuf,
        /// Version found in the file.
        found: i64,
        /// Newest version this build can migrate to.
        supported: i64,
    },
    /// The file is not an SQLite database at all (another kind of file, or a corrupt one); it is left
    /// untouched.
    #[error(
        "{}: not a results store: the file is not an SQLite database (another kind of file, or corrupt); give --store a new file or an existing store",
        .path.display()
    )]
    NotADatabase {
        /// The file.
        path: PathBuf,
    },
    /// The file is an SQLite database but not a results store (it has tables and no `schema_version`); it
    /// is left untouched.
    #[error(
        "{}: not a bouncelab results store: an SQLite database with {tables} other table(s) ({first} …); give --store a new file or an existing store",
        .path.display()
    )]
    Foreign {
        /// The database file.
        path: PathBuf,
        /// How many tables it holds.
        tables: usize,
        /// The first few table names, comma separated.
        first: String,
    },
    /// A table name given to the CSV export does not exist.
    #[error("unknown table `{name}`; the tables are: {known}")]
    UnknownTable {
        /// The name asked for.
        name: String,
        /// The known names, comma separated.
        known: String,
    },
    /// Reading or writing a file (CSV export, clip fingerprint) failed.
    #[error("{}: {source}", .path.display())]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// Writing CSV failed.
    #[error("{}: table `{table}`: CSV export failed: {source}", .path.display())]
    Csv {
        /// The database file.
        path: PathBuf,
        /// The table being exported.
        table: &'static str,
        /// The CSV error.
        #[source]
        source: csv::Error,
    },
}

impl StoreError {
    /// Whether SQLite answered that the database is busy or locked by another connection.
    pub(crate) fn is_busy(&self) -> bool {
        let code = match self {
            StoreError::Open { source, .. } | StoreError::Sql { source, .. } => source.sqlite_error_code(),
            _ => None,
        };
        matches!(
            code,
            Some(rusqlite::ErrorCode::DatabaseBusy | rusqlite::ErrorCode::DatabaseLocked)
        )
    }
}
