//! A mosquitto on a free loopback port, for the broker tests and the broker examples (which
//! include this file: it needs nothing but the standard library).
#![allow(dead_code)]

use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A mosquitto on a free loopback port, stopped when dropped.
pub struct Broker {
    child: Child,
    /// Its configuration file, removed with it.
    conf: Option<std::path::PathBuf>,
    /// Its loopback port.
    pub port: u16,
}

impl Broker {
    /// Starts one, or `None` (with a line saying why) when mosquitto is not installed.
    pub fn start() -> Option<Broker> {
        let port = free_port();
        Broker::on(port)
    }

    /// Starts one on `port`, or `None` when mosquitto is not installed.
    pub fn on(port: u16) -> Option<Broker> {
        Broker::spawned(port, &["-p", &port.to_string()])
    }

    /// Starts one on a free port whose own sockets send small frames at once
    /// (`set_tcp_nodelay true`) or wait for the peer's acknowledgement (`false`: ~40 ms
    /// stalls), from a configuration file in the temporary directory; `None` when mosquitto is
    /// not installed.
    pub fn tuned(nodelay: bool) -> Option<Broker> {
        let port = free_port();
        let conf = std::env::temp_dir().join(format!("bmlr_mosquitto_{port}.conf"));
        let settings =
            format!("listener {port} 127.0.0.1\nallow_anonymous true\nset_tcp_nodelay {nodelay}\n");
        std::fs::write(&conf, settings).ok()?;
        let mut broker = Broker::spawned(port, &["-c", conf.to_str()?])?;
        broker.conf = Some(conf);
        Some(broker)
    }

    fn spawned(port: u16, args: &[&str]) -> Option<Broker> {
        // (Debian installs it in /usr/sbin, which a user's PATH may lack)
        let spawn = |program: &str| {
            Command::new(program)
                .args(args)
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
        };
        let child = spawn("mosquitto").or_else(|_| spawn("/usr/sbin/mosquitto"));
        let Ok(child) = child else {
            eprintln!("skipped: mosquitto is not installed (Debian package mosquitto; .ci/run installs it)");
            return None;
        };
        let until = Instant::now() + Duration::from_secs(5);
        while std::net::TcpStream::connect(("127.0.0.1", port)).is_err() {
            assert!(
                Instant::now() < until,
                "mosquitto did not start on port {port}"
            );
            std::thread::sleep(Duration::from_millis(20));
        }
        Some(Broker {
            child,
            conf: None,
            port,
        })
    }

    /// Its process id (for the CPU time it used).
    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// `mqtt://127.0.0.1:PORT`.
    pub fn url(&self) -> String {
        format!("mqtt://127.0.0.1:{}", self.port)
    }
}

impl Drop for Broker {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        if let Some(conf) = &self.conf {
            let _ = std::fs::remove_file(conf);
        }
    }
}

/// A loopback port nobody listens on now.
pub fn free_port() -> u16 {
    let l = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    l.local_addr().unwrap().port()
}
