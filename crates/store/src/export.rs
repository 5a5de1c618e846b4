//! CSV export of every table.

use std::fs;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use rusqlite::types::ValueRef;

use crate::error::{Result, StoreError};
use crate::schema::Table;
use crate::store::Store;

fn cell(v: ValueRef<'_>) -> String {
    match v {
        ValueRef::Null => String::new(),
        ValueRef::Integer(i) => i.to_string(),
        // Rust's shortest representation that reads back to the same f64.
        ValueRef::Real(x) => x.to_string(),
        ValueRef::Text(t) => String::from_utf8_lossy(t).into_owned(),
        ValueRef::Blob(b) => b.iter().map(|x| format!("{x:02x}")).collect(),
    }
}

impl Store {
    /// Writes `table` as CSV to `out`: a header row of [`Table::columns`], then every row in primary-key
    /// order. NULL (and so NaN) is an empty cell; JSON columns are their JSON text. Returns the number of
    /// data rows.
    pub fn export_csv(&self, table: Table, out: impl Write) -> Result<u64> {
        let name = table.name();
        let csv_err = |source| StoreError::Csv {
            path: self.path().to_path_buf(),
            table: name,
            source,
        };
        let sql_err = |source| StoreError::Sql {
            path: self.path().to_path_buf(),
            table: name,
            source,
        };
        let columns = table.columns();
        let mut w = csv::Writer::from_writer(out);
        w.write_record(columns).map_err(csv_err)?;
        let mut stmt = self
            .conn()
            .prepare(&format!(
                "SELECT {} FROM {name} ORDER BY {}",
                columns.join(", "),
                table.order_by()
            ))
            .map_err(sql_err)?;
        let mut rows = stmt.query([]).map_err(sql_err)?;
        let mut n = 0;
        while let Some(row) = rows.next().map_err(sql_err)? {
            let mut record = Vec::with_capacity(columns.len());
            for i in 0..columns.len() {
                record.push(cell(row.get_ref(i).map_err(sql_err)?));
            }
            w.write_record(&record).map_err(csv_err)?;
            n += 1;
        }
        w.flush().map_err(|e| csv_err(e.into()))?;
        Ok(n)
    }

    /// Writes every table as `<dir>/<table>.csv` (creating `dir`) and returns the files written.
    pub fn export_all_csv(&self, dir: impl AsRef<Path>) -> Result<Vec<PathBuf>> {
        let dir = dir.as_ref();
        fs::create_dir_all(dir).map_err(|source| StoreError::Io {
            path: dir.to_path_buf(),
            source,
        })?;
        let mut written = Vec::new();
        for table in Table::ALL {
            let file = dir.join(format!("{}.csv", table.name()));
            let f = fs::File::create(&file).map_err(|source| StoreError::Io {
                path: file.clone(),
                source,
            })?;
            let mut w = BufWriter::new(f);
            self.export_csv(table, &mut w)?;
            w.flush().map_err(|source| StoreError::Io {
                path: file.clone(),
                source,
            })?;
            written.push(file);
        }
        Ok(written)
    }
}
