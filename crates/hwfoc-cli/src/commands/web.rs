//! `hwfoc web [--listen ADDR]`: the browser app (web/, built into the binary by the build
//! script), served on loopback unless told otherwise. The page decodes files and live ports in
//! the browser itself: nothing but the page's own files crosses this server.

use std::net::SocketAddr;
use std::sync::atomic::Ordering;
use std::time::Duration;

use clap::Args;

use crate::error::CliError;
use crate::stop;

/// The page's files: `(path under web/dist, content)`, made by `build_web.rs`.
pub const FILES: &[(&str, &[u8])] = include!(concat!(env!("OUT_DIR"), "/web_files.rs"));

/// Arguments of `hwfoc web`.
#[derive(Debug, Args)]
pub struct WebArgs {
    /// The address to serve on. Another computer can open the page only if this is not a
    /// loopback address (e.g. 0.0.0.0:8345); Web Serial then needs HTTPS, which this server
    /// does not give (ports are opened from the page on http://localhost only).
    #[arg(long, value_name = "ADDR", default_value = "127.0.0.1:8345")]
    pub listen: SocketAddr,
}

/// The content type of a file, by its extension.
pub fn content_type(path: &str) -> &'static str {
    match path.rsplit('.').next() {
        Some("html") => "text/html; charset=utf-8",
        Some("js") => "text/javascript; charset=utf-8",
        Some("css") => "text/css; charset=utf-8",
        Some("wasm") => "application/wasm",
        Some("json") | Some("webmanifest") => "application/json",
        Some("svg") => "image/svg+xml",
        Some("png") => "image/png",
        _ => "application/octet-stream",
    }
}

/// The embedded file for a request's path (`/` is `index.html`; a query is ignored).
pub fn file_for(url: &str) -> Option<&'static [u8]> {
    let path = url.split(['?', '#']).next().unwrap_or("");
    let path = path.trim_start_matches('/');
    let path = if path.is_empty() { "index.html" } else { path };
    FILES
        .iter()
        .find(|(name, _)| *name == path)
        .map(|(_, bytes)| *bytes)
}

/// Serves the page until Ctrl-C.
pub fn run(args: &WebArgs) -> Result<(), CliError> {
    let server = tiny_http::Server::http(args.listen).map_err(|e| CliError::Listen {
        listen: args.listen.to_string(),
        message: e.to_string(),
    })?;
    let at = server
        .server_addr()
        .to_ip()
        .map_or_else(|| args.listen.to_string(), |a| a.to_string());
    eprintln!("hwfoc web: http://{at}/ (Ctrl-C stops)");
    let stop = stop::interrupted();
    while !stop.load(Ordering::Relaxed) {
        let request = match server.recv_timeout(Duration::from_millis(200)) {
            Ok(Some(request)) => request,
            Ok(None) => continue,
            Err(e) => {
                return Err(CliError::Listen {
                    listen: at,
                    message: e.to_string(),
                });
            }
        };
        let path = request
            .url()
            .split(['?', '#'])
            .next()
            .unwrap_or("")
            .to_owned();
        let response = match file_for(&path) {
            Some(bytes) => {
                let name = if path == "/" { "index.html" } else { &path };
                tiny_http::Response::from_data(bytes)
                    .with_header(header("Content-Type", content_type(name)))
                    .with_header(header("Cache-Control", "no-cache"))
            }
            None => tiny_http::Response::from_data(&b"not found"[..]).with_status_code(404),
        };
        // A browser that went away mid-answer is not the server's failure.
        let _ = request.respond(response);
    }
    Ok(())
}

/// A response header from two static strings.
fn header(name: &'static str, value: &'static str) -> tiny_http::Header {
    tiny_http::Header::from_bytes(name.as_bytes(), value.as_bytes())
        .expect("a header of ASCII names and values")
}
