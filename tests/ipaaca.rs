//! ipaaca as ipaacar speaks it, tested with the ipaaca library itself: `tests/peers/ipaaca_peer.py`
//! is a planner written with ipaacar-python (PyPI; GPL-3, so it runs as a separate process from
//! a venv and is never vendored) on two channels, against `bmlr serve --mqtt … --ipaaca
//! default,Alice` and a mosquitto started on a free port. The peer checks: a componentNotify is
//! answered; each channel gets its own block's start and end within 10 s as `{"bmlfeedback":
//! XML}` messages through its InputBuffer and nothing of the other's; garbage gives a warning
//! there and the next block runs; a `realizerRequest` IU is updated to IN_EXEC, DONE (and ERROR
//! for a block that cannot be read), keeping its own keys.
//!
//! The Python with ipaacar is `$BMLR_IPAACA_PYTHON` (`.ci/run` makes a venv), else `python3` if
//! it can import ipaacar; without one the test says "skipped" (and `.ci/run` fails on that).

#[path = "common/broker.rs"]
mod kit;

use std::process::Command;

use kit::{Broker, Served};

fn ipaaca_python() -> Option<String> {
    kit::python_with("BMLR_IPAACA_PYTHON", "ipaacar.components")
}

#[test]
fn ipaacar_python_planners_on_two_channels_are_served() {
    let Some(python) = ipaaca_python() else {
        eprintln!("skipped: ipaacar-python is not installed (set BMLR_IPAACA_PYTHON to a python with `pip install ipaacar-python`; .ci/run does)");
        return;
    };
    let Some(broker) = Broker::start() else {
        return;
    };
    let url = broker.url();
    let _realizer = Served(
        Command::new(env!("CARGO_BIN_EXE_bmlr"))
            .args([
                "serve",
                "--mqtt",
                &url,
                "--ipaaca",
                "default,Alice",
                "--name",
                "asap",
            ])
            .spawn()
            .expect("bmlr runs"),
    );
    let address = format!("127.0.0.1:{}", broker.port);
    kit::run_peer(&python, "ipaaca_peer.py", &address, "ipaacar", 11);
}
