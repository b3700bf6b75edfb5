//! Navigation speed over a whole swaying recording: three cycles, each 60 s at rest and
//! two 300 s sways (5 s and 10 s), at 100 Hz (198 000 samples).

use criterion::{Criterion, criterion_group, criterion_main};
use ratecal_physics::nav::{align, navigate};
use ratecal_physics::{AxisMotion, DEG, Geometry, ImuErrors, Mat3, Site, TableState, Vec3};
use std::f64::consts::PI;

fn samples() -> (Vec<f64>, Vec<Vec3>, Vec<Vec3>) {
    let site = Site {
        latitude_deg: 55.7,
        gravity_mps2: 9.8156,
    };
    let geo = Geometry::vertical_outer();
    let imu = ImuErrors {
        lever_m: Mat3::new(0.0, 0.004, -0.003, 0.003, 0.0, 0.005, -0.006, 0.002, 0.0),
        ..Default::default()
    };
    let (mut t, mut w, mut f) = (Vec::new(), Vec::new(), Vec::new());
    let hz = 100.0;
    for tk in (0..(3.0 * 660.0 * hz) as usize).map(|k| k as f64 / hz) {
        let s = tk % 660.0;
        let period = if s < 360.0 { 5.0 } else { 10.0 };
        let wv = 2.0 * PI / period;
        let outer = if s < 60.0 {
            AxisMotion::default()
        } else {
            AxisMotion {
                angle: PI / 2.0 * (wv * s).sin(),
                rate: PI / 2.0 * wv * (wv * s).cos(),
                accel: -PI / 2.0 * wv * wv * (wv * s).sin(),
            }
        };
        let state = TableState {
            outer,
            inner: AxisMotion::default(),
        };
        let (a, g) = imu.measure(&state, &geo, &site, 20.0);
        t.push(tk);
        w.push(g * DEG);
        f.push(a);
    }
    (t, w, f)
}

fn bench(c: &mut Criterion) {
    let site = Site {
        latitude_deg: 55.7,
        gravity_mps2: 9.8156,
    };
    let (t, w, f) = samples();
    let c0 = align(&f[0], &w[0], site.gravity_mps2).expect("at rest");
    c.bench_function("navigate a swaying recording (198k samples)", |b| {
        b.iter(|| navigate(&t, &w, &f, &c0, &site, false))
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = bench
}
criterion_main!(benches);
