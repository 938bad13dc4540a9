//! Live CAN buses among ports: an SLCAN adapter on a pseudo-terminal (frames it sends arrive
//! as 16-byte records with their times; the set-up and the ESC id requests appear on its
//! line), and a SocketCAN `vcan0` where the kernel has one.

#![cfg(unix)]

use std::io::{Read, Write};
use std::os::fd::AsFd;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use hwfoc::dronecan::CanFrame;
use hwfoc_ports::clock::unix_now_ns;
use hwfoc_ports::serial::{PortEvent, PortSet};

/// The records of the first `n` data events within 5 s, with their times.
fn frames(set: &PortSet, n: usize) -> Vec<(u64, CanFrame)> {
    let until = Instant::now() + Duration::from_secs(5);
    let mut got = Vec::new();
    while got.len() < n && Instant::now() < until {
        if let Some(PortEvent::Data { port, t_ns, bytes }) =
            set.next_event(Duration::from_millis(100))
        {
            assert_eq!((port, bytes.len()), (0, 16));
            let record: [u8; 16] = bytes.try_into().unwrap();
            got.push((t_ns, CanFrame::from_socketcan_record(&record).unwrap()));
        }
    }
    got
}

#[test]
fn an_slcan_adapter_on_a_pty_is_a_can_port() {
    let pty = nix::pty::openpty(None, None).unwrap();
    let slave = nix::unistd::ttyname(pty.slave.as_fd()).unwrap();
    let names = vec![format!("slcan:{}", slave.display())];
    let mut master = std::fs::File::from(pty.master);
    // What the adapter is sent, read on a thread of its own (it ends when the port closes).
    let sent = Arc::new(Mutex::new(Vec::new()));
    let mut reader = master.try_clone().unwrap();
    let log = Arc::clone(&sent);
    std::thread::spawn(move || {
        let mut buf = [0u8; 256];
        while let Ok(n) = reader.read(&mut buf) {
            if n == 0 {
                break;
            }
            log.lock().unwrap().extend_from_slice(&buf[..n]);
        }
    });
    let set = PortSet::open(&names, 19200).unwrap();
    assert!(set.is_can(0) && !set.is_can(1));
    let before = unix_now_ns();
    master
        .write_all(b"t1231AB\rT1004E27F200C01234\rF00\r")
        .unwrap();
    let got = frames(&set, 2);
    let after = unix_now_ns();
    assert_eq!(
        got.iter().map(|g| g.1).collect::<Vec<_>>(),
        [
            CanFrame::standard(0x123, &[0xAB]).unwrap(),
            CanFrame::extended(0x1004_E27F, &[0x00, 0xC0]).unwrap()
        ]
    );
    assert!(got.iter().all(|g| g.0 >= before && g.0 <= after), "{got:?}");
    // Set-up at 500 kbit/s, then GetEscID [0] from node 127 at priority 16, once a second,
    // the transfer id counting up.
    std::thread::sleep(Duration::from_millis(1300));
    drop(set);
    let sent = String::from_utf8(sent.lock().unwrap().clone()).unwrap();
    assert!(sent.starts_with("\rC\rS6\rO\r"), "{sent:?}");
    assert!(sent.contains("T104E2D7F200C0\r"), "{sent:?}");
    assert!(sent.contains("T104E2D7F200C1\r"), "{sent:?}");
}

#[test]
fn a_refused_bit_rate_is_an_error_naming_the_adapter() {
    let pty = nix::pty::openpty(None, None).unwrap();
    let slave = nix::unistd::ttyname(pty.slave.as_fd()).unwrap();
    let spec = format!("slcan:{}:250k", slave.display());
    let mut master = std::fs::File::from(pty.master);
    let mut answer = master.try_clone().unwrap();
    std::thread::spawn(move || {
        // Acks `\r` and `C`, refuses the bit rate.
        let mut buf = [0u8; 64];
        let mut seen = Vec::new();
        while let Ok(n) = answer.read(&mut buf) {
            if n == 0 {
                break;
            }
            seen.extend_from_slice(&buf[..n]);
            if seen.ends_with(b"C\r") {
                let _ = answer.write_all(b"\r\r");
            }
            if seen.ends_with(b"S5\r") {
                let _ = answer.write_all(b"\x07");
            }
        }
    });
    let e = hwfoc_ports::can::CanBus::open(&spec, false).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!("{spec}: the adapter refused the bit rate 250000 bit/s")
    );
    let _ = master.flush();
}

/// SocketCAN: a frame sent on vcan0 by one socket arrives at a port set reading it.
#[cfg(target_os = "linux")]
#[test]
#[ignore = "needs a vcan interface (modprobe vcan; ip link add dev vcan0 type vcan; ip link set up vcan0)"]
fn a_vcan_interface_is_a_can_port() {
    let names = vec!["can:vcan0".to_string()];
    let set = PortSet::open(&names, 19200).unwrap();
    assert!(set.is_can(0));
    let mut other = hwfoc_ports::can::CanBus::open("can:vcan0", false).unwrap();
    let frame = CanFrame::extended(0x104E_5201, &[1, 2, 3, 0xC0]).unwrap();
    other.send(&frame).unwrap();
    let got = frames(&set, 1);
    assert_eq!(got.len(), 1);
    assert_eq!(got[0].1, frame);
    // The set's id request reaches the other socket.
    let until = Instant::now() + Duration::from_secs(3);
    let mut asked = false;
    while !asked && Instant::now() < until {
        if let Some((_, f)) = other.recv(Duration::from_millis(100)).unwrap() {
            asked = f.id() == 0x104E_2D7F && f.data() == [0x00, 0xC0];
        }
    }
    assert!(asked);
}
