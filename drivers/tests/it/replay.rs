//! The replay driver plays a recording folder's streams in time, read through the
//! recording crate: both streams on the table's clock, and a refused stream named at its
//! file, line and column.

use ratecal_drivers::replay::{ReplayImu, ReplayTable};
use ratecal_drivers::{ImuDriver, Station, TableDriver};
use std::time::Duration;

fn folder(imu: &str, table: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("imu.csv"), imu).unwrap();
    std::fs::write(dir.path().join("table.csv"), table).unwrap();
    dir
}

const IMU: &str = "t,ax,ay,az,gx,gy,gz,temp\n10.05,0.1,0.2,9.8,1,2,3,22.5\n10.15,0.1,0.2,9.8,1,2,3,22.6\n\"10.25\",0.1,0.2,9.8,1,2,3,22.7\n";
const TABLE: &str = "t,outer,inner,outer_rate,inner_rate\r\n10,0,90,0,0\r\n10.2,1,90,5,0\r\n";

#[tokio::test(start_paused = true)]
async fn both_streams_play_on_the_tables_clock() {
    let dir = folder(IMU, TABLE);
    let path = dir.path().to_str().unwrap();
    let station = Station::default_sim();
    let mut table = ReplayTable::open(path, &station).unwrap();
    let mut imu = ReplayImu::open(path, &station).unwrap();
    tokio::time::sleep(Duration::from_millis(160)).await;
    let (mut fb, mut samples) = (Vec::new(), Vec::new());
    table.read(&mut fb).await.unwrap();
    imu.read(&mut samples).await.unwrap();
    assert_eq!(fb.len(), 1);
    assert_eq!(
        (fb[0].t, fb[0].inner_deg, fb[0].ambient_c),
        (0.0, 90.0, None)
    );
    let t: Vec<f64> = samples.iter().map(|s| s.t).collect();
    assert_eq!(t.len(), 2, "{t:?}");
    assert!(
        (t[0] - 0.05).abs() < 1e-9 && (t[1] - 0.15).abs() < 1e-9,
        "{t:?}"
    );
    assert_eq!(samples[1].gyro, [1.0, 2.0, 3.0]);
    assert_eq!(samples[1].temp_c, Some(22.6));
    tokio::time::sleep(Duration::from_secs(1)).await;
    table.read(&mut fb).await.unwrap();
    imu.read(&mut samples).await.unwrap();
    assert_eq!((fb.len(), samples.len()), (2, 3));
    assert_eq!(fb[1].outer_rate_dps, 5.0);
}

#[test]
fn a_refused_stream_is_located() {
    let dir = folder(
        &IMU.replace("0.1,0.2,9.8,1,2,3,22.6", "0.1,x,9.8,1,2,3,22.6"),
        TABLE,
    );
    let path = dir.path().to_str().unwrap();
    let station = Station::default_sim();
    let e = ReplayImu::open(path, &station).unwrap_err();
    let at = format!("{}:3:", dir.path().join("imu.csv").display());
    assert!(e.to_string().contains(&at), "{e}");
    assert!(
        e.to_string().contains("`x` in column `ay` is not a number"),
        "{e}"
    );
    let dir = folder(IMU, "t,outer,inner,outer_rate\n0,0,0,0\n1,0,0,0\n");
    let e = ReplayTable::open(dir.path().to_str().unwrap(), &station).unwrap_err();
    assert!(e.to_string().contains("missing column `inner_rate`"), "{e}");
}
