//! Reads a recording folder whole, or segment by segment through the time index, and says
//! how long it took: `cargo run --release -p ratecal-recording --example spans -- DIR
//! [whole|spans]` (measure peak memory with `/usr/bin/time -v`).

use ratecal_recording::{Recording, read};
use std::path::Path;
use std::time::Instant;

fn main() -> miette::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let dir = Path::new(args.get(1).map_or(".", String::as_str));
    let t = Instant::now();
    let (mut imu, mut table) = (0, 0);
    if args.get(2).map(String::as_str) == Some("whole") {
        let rec = read(dir)?;
        (imu, table) = (rec.imu.t.len(), rec.table.t.len());
    } else {
        let open = Recording::open(dir)?;
        eprintln!("opened in {:.2?}", t.elapsed());
        for seg in &open.manifest().segments {
            let rows = open.read_span(seg.t_start, seg.t_end)?;
            imu += rows.imu.t.len();
            table += rows.table.t.len();
        }
    }
    eprintln!("{imu} IMU rows, {table} table rows in {:.2?}", t.elapsed());
    Ok(())
}
