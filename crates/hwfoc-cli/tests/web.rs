//! `hwfoc web`: the browser app served from the binary on loopback, every file of it the build's,
//! and Ctrl-C ending it cleanly.

mod common;

use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::Duration;

#[cfg(unix)]
use common::Running;
#[cfg(unix)]
use nix::sys::signal::Signal;

/// A GET of `path` from `addr`: (status line, headers and body as bytes).
fn get(addr: &str, path: &str) -> (String, Vec<u8>) {
    let mut stream = TcpStream::connect(addr).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(10)))
        .unwrap();
    write!(stream, "GET {path} HTTP/1.0\r\nHost: {addr}\r\n\r\n").unwrap();
    let mut answer = Vec::new();
    stream.read_to_end(&mut answer).unwrap();
    let head_end = answer.windows(4).position(|w| w == b"\r\n\r\n").unwrap();
    let head = String::from_utf8_lossy(&answer[..head_end]).into_owned();
    (head, answer[head_end + 4..].to_vec())
}

#[cfg(unix)]
#[test]
fn web_serves_the_page_and_its_webassembly_on_loopback_and_stops_on_ctrl_c() {
    let mut web = Running::start(&["web", "--listen", "127.0.0.1:0"]);
    let line = web.wait_for("http://", Duration::from_secs(10));
    let addr = line
        .split("http://")
        .nth(1)
        .and_then(|rest| rest.split('/').next())
        .unwrap()
        .to_owned();
    assert!(addr.starts_with("127.0.0.1:"), "{line}");

    let (head, body) = get(&addr, "/");
    assert!(head.contains(" 200 OK"), "{head}");
    assert!(head.contains("text/html"), "{head}");
    let page = String::from_utf8(body).unwrap();
    assert!(page.contains("src/main.js"), "{page}");

    let (head, body) = get(&addr, "/pkg/hwfoc_web_bg.wasm");
    assert!(head.contains("application/wasm"), "{head}");
    assert_eq!(&body[..4], b"\0asm", "a WebAssembly module");
    let (head, body) = get(&addr, "/src/hwfoc.js?v=1");
    assert!(head.contains("text/javascript"), "{head}");
    assert!(
        String::from_utf8(body)
            .unwrap()
            .contains("export class Session")
    );

    let (head, _) = get(&addr, "/../Cargo.toml");
    assert!(head.contains(" 404 "), "{head}");

    web.signal(Signal::SIGINT);
    assert!(web.wait(Duration::from_secs(5)), "{}", web.stderr());
}

#[test]
fn web_says_which_address_it_cannot_listen_on() {
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = taken.local_addr().unwrap().to_string();
    let out = common::run(common::hwfoc().args(["web", "--listen", &addr]));
    common::assert_fails_with(&out, &format!("cannot listen on {addr}"));
}
