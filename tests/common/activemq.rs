//! An ActiveMQ for the tests: Debian's `activemq` (its jar run by its Java) on two free loopback
//! ports (OpenWire for the JMS peer, STOMP for the realizer), without persistence or JMX, in a
//! directory of its own; stopped when dropped. Without the package a test says "skipped".
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// Where Debian installs ActiveMQ (`$ACTIVEMQ_HOME` overrides).
fn home() -> PathBuf {
    std::env::var_os("ACTIVEMQ_HOME")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("/usr/share/activemq"))
}

/// A running ActiveMQ.
pub struct ActiveMq {
    child: Child,
    base: PathBuf,
    /// Its OpenWire port (JMS clients).
    pub openwire: u16,
    /// Its STOMP port.
    pub stomp: u16,
}

impl ActiveMq {
    /// Starts one on free ports, or `None` with a line saying why (the package is missing).
    pub fn start() -> Option<ActiveMq> {
        let (openwire, stomp) = (super::kit::free_port(), super::kit::free_port());
        ActiveMq::on(openwire, stomp)
    }

    /// Starts one on these ports (again, after [`ActiveMq::stop`]).
    pub fn on(openwire: u16, stomp: u16) -> Option<ActiveMq> {
        let jar = home().join("bin/activemq.jar");
        if !jar.exists() || Command::new("java").arg("-version").output().is_err() {
            eprintln!(
                "skipped: ActiveMQ is not installed (Debian package activemq, with its Java; .ci/run installs it)"
            );
            return None;
        }
        let base = std::env::temp_dir().join(format!("bmlr-amq-{}-{stomp}", std::process::id()));
        std::fs::create_dir_all(base.join("data")).expect("a directory for the broker");
        let uri = format!(
            "broker:(tcp://127.0.0.1:{openwire},stomp://127.0.0.1:{stomp}?transport.tcpNoDelay=true)?persistent=false&useJmx=false"
        );
        let child = Command::new("java")
            .arg("-Xmx256m")
            .arg(format!("-Dactivemq.home={}", home().display()))
            .arg(format!("-Dactivemq.base={}", base.display()))
            .arg(format!("-Dactivemq.data={}", base.join("data").display()))
            .arg("-jar")
            .arg(&jar)
            .args(["start", &uri])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("java runs");
        let broker = ActiveMq {
            child,
            base,
            openwire,
            stomp,
        };
        let until = Instant::now() + Duration::from_secs(60);
        while std::net::TcpStream::connect(("127.0.0.1", stomp)).is_err() {
            assert!(
                Instant::now() < until,
                "ActiveMQ did not listen on {stomp} in 60 s"
            );
            std::thread::sleep(Duration::from_millis(50));
        }
        Some(broker)
    }

    /// The realizer's address.
    pub fn stomp_url(&self) -> String {
        format!("stomp://127.0.0.1:{}", self.stomp)
    }

    /// The JMS peer's address.
    pub fn openwire_url(&self) -> String {
        format!("tcp://127.0.0.1:{}", self.openwire)
    }

    /// Kills it (as a crash would) and waits until it is gone.
    pub fn stop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }

    /// The class path of the JMS client jars Debian's package ships (for the Java peer).
    pub fn client_classpath() -> String {
        let lib = home().join("lib");
        [
            "activemq-client.jar",
            "geronimo-jms_1.1_spec.jar",
            "geronimo-j2ee-management-1.1-spec.jar",
            "hawtbuf.jar",
            "slf4j-api.jar",
        ]
        .iter()
        .map(|j| lib.join(j).display().to_string())
        .collect::<Vec<_>>()
        .join(":")
    }
}

impl Drop for ActiveMq {
    fn drop(&mut self) {
        self.stop();
        let _ = std::fs::remove_dir_all(&self.base);
    }
}
