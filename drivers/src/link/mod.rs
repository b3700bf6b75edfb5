//! Links to hardware: where a device is (a TCP address or a serial port), how to open it
//! as one async byte stream, and how its clock maps onto the host's.

mod clock;
mod imu;
mod table;

pub use clock::ClockMap;
pub use imu::FramedImu;
pub use table::LinkTable;

use crate::{DriverError, DriverErrorKind};
use std::time::Duration;
use tokio::io::{AsyncRead, AsyncWrite};

/// Any async byte stream a protocol can run over.
pub trait ByteStream: AsyncRead + AsyncWrite + Unpin + Send {}

impl<T: AsyncRead + AsyncWrite + Unpin + Send> ByteStream for T {}

/// An opened link.
pub type BoxStream = Box<dyn ByteStream>;

/// Where a device is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Endpoint {
    /// `host:port`.
    Tcp(String),
    /// A serial port (device path) and its baud rate.
    Serial(String, u32),
}

impl std::fmt::Display for Endpoint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Endpoint::Tcp(a) => write!(f, "tcp {a}"),
            Endpoint::Serial(p, b) => write!(f, "serial {p} at {b} Bd"),
        }
    }
}

/// Opens a link within `timeout`.
pub async fn connect(endpoint: &Endpoint, timeout: Duration) -> Result<BoxStream, DriverError> {
    let open = async {
        match endpoint {
            Endpoint::Tcp(address) => {
                let s = tokio::net::TcpStream::connect(address).await?;
                s.set_nodelay(true)?;
                Ok::<BoxStream, std::io::Error>(Box::new(s))
            }
            Endpoint::Serial(port, baud) => {
                use tokio_serial::SerialPort;
                let s = tokio_serial::SerialStream::open(
                    &tokio_serial::new(port, *baud).exclusive(false),
                )
                .map_err(std::io::Error::from)?;
                // Bytes the device sent before anyone listened are stale.
                let _ = s.clear(tokio_serial::ClearBuffer::Input);
                Ok(Box::new(s) as BoxStream)
            }
        }
    };
    match tokio::time::timeout(timeout, open).await {
        Ok(Ok(s)) => Ok(s),
        Ok(Err(e)) => Err(DriverError::new(
            DriverErrorKind::Transport,
            format!("cannot open {endpoint}: {e}"),
        )),
        Err(_) => Err(DriverError::new(
            DriverErrorKind::Timeout,
            format!("{endpoint} did not open within {} s", timeout.as_secs_f64()),
        )),
    }
}
