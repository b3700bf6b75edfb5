//! `ratecal emulate`: serves a station file's simulated station in real time over the
//! hardware protocols (docs/protocols.md), so that `ratecal run PROC --station FILE` can
//! rehearse against it. Exit codes: 0 stopped (Ctrl-C), 1 input error, 2 usage.

use miette::{Report, miette};
use ratecal_drivers::emulate::{Emulator, Served, connecting_station};
use std::io::Write;
use std::net::SocketAddr;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `ratecal emulate`.
#[derive(clap::Args)]
pub struct Args {
    /// Station file to emulate: its drivers are ignored (the station is simulated), its
    /// faults are played (the link faults by the emulator).
    #[arg(long)]
    station: PathBuf,
    /// Where to serve: the table on PORT, the IMU on PORT + 1 (port 0 picks free ports).
    #[arg(long, value_name = "HOST:PORT", default_value = "127.0.0.1:0")]
    listen: String,
    /// Write the station file that connects to this emulator.
    #[arg(long, value_name = "FILE")]
    write_station: Option<PathBuf>,
    /// Serve the serial variant on pseudo-terminals (printing their paths) instead of TCP.
    #[arg(long)]
    pty: bool,
    /// Seed of the simulated station.
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

/// Runs the subcommand.
pub fn main(args: Args) -> ExitCode {
    match run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(report) => {
            eprintln!("{report:?}");
            ExitCode::from(1)
        }
    }
}

fn run(args: Args) -> Result<(), Report> {
    let st = ratecal_ops::run::station_file(&args.station)?;
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .map_err(|e| miette!("cannot start the runtime: {e}"))?;
    rt.block_on(async {
        let emulator = Emulator::new(st.station, args.seed, true);
        let (table, imu, serving) = if args.pty {
            serve_pty(emulator)?
        } else {
            serve_tcp(emulator, &args.listen).await?
        };
        println!("table: {} (line protocol)", shown(&table));
        println!("imu: {} (binary frames)", shown(&imu));
        if let Some(path) = &args.write_station {
            let text = connecting_station(&st.yaml, &table, &imu).map_err(|e| miette!("{e}"))?;
            // Written whole, then renamed: a script waiting for the file never reads half.
            let tmp = path.with_extension("tmp");
            std::fs::write(&tmp, text)
                .and_then(|()| std::fs::rename(&tmp, path))
                .map_err(|e| miette!("cannot write {}: {e}", path.display()))?;
            println!("station: {}", path.display());
        }
        let _ = std::io::stdout().flush();
        tokio::select! {
            _ = serving => {}
            _ = tokio::signal::ctrl_c() => eprintln!("emulate: stopped"),
        }
        Ok(())
    })
}

fn shown(s: &Served) -> String {
    match s {
        Served::Tcp(a) => format!("tcp {a}"),
        Served::Pty(p) => format!("pty {p}"),
    }
}

type Serving = tokio::task::JoinHandle<()>;

async fn serve_tcp(
    emulator: std::sync::Arc<Emulator>,
    listen: &str,
) -> Result<(Served, Served, Serving), Report> {
    let addr: SocketAddr = listen.parse().map_err(|e| {
        miette!(
            help = "write an address and a port, e.g. 127.0.0.1:5025 (port 0 picks free ports)",
            "--listen `{listen}`: {e}"
        )
    })?;
    let bind = |a: SocketAddr| async move {
        tokio::net::TcpListener::bind(a).await.map_err(|e| {
            miette!(
                help = "choose another port, or 0 for free ones",
                "cannot listen on {a}: {e}"
            )
        })
    };
    let table = bind(addr).await?;
    let mut imu_addr = addr;
    if addr.port() != 0 {
        imu_addr.set_port(addr.port().checked_add(1).ok_or_else(|| {
            miette!(
                help = "the IMU is served on PORT + 1",
                "--listen port {} leaves no port for the IMU",
                addr.port()
            )
        })?);
    }
    let imu = bind(imu_addr).await?;
    let local = |l: &tokio::net::TcpListener| {
        l.local_addr()
            .map(|a| Served::Tcp(a.to_string()))
            .map_err(|e| miette!("{e}"))
    };
    let (t, i) = (local(&table)?, local(&imu)?);
    Ok((t, i, tokio::spawn(emulator.serve_tcp(table, imu))))
}

#[cfg(unix)]
fn serve_pty(emulator: std::sync::Arc<Emulator>) -> Result<(Served, Served, Serving), Report> {
    let (t, i, task) = emulator
        .serve_pty()
        .map_err(|e| miette!("cannot open pseudo-terminals: {e}"))?;
    Ok((Served::Pty(t), Served::Pty(i), task))
}

#[cfg(not(unix))]
fn serve_pty(_: std::sync::Arc<Emulator>) -> Result<(Served, Served, Serving), Report> {
    Err(miette!("--pty needs pseudo-terminals (Unix)"))
}
