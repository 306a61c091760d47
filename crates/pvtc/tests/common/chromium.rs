//! Headless Chromium driven over the DevTools protocol, for the HTML view's tests.
//!
//! Owns starting Chromium with `--remote-debugging-pipe` (its descriptors 3 and 4 are two
//! FIFOs the shell opens, so no unsafe code is needed), one page session, the protocol's
//! calls (JSON messages ending in a NUL byte) and the events seen meanwhile. It must not
//! judge a page: each test asserts on what it returns.

use serde_json::{json, Value};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{channel, Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

/// The flags that let Chromium run headless here without reaching for any network
/// (the environment notes in /work/.library/env/machines/rust.md).
const FLAGS: [&str; 9] = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
    "--disable-quic",
    "--remote-debugging-pipe",
];

/// The Chromium binary on `PATH`, if any.
pub fn find() -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    ["chromium", "chromium-browser", "google-chrome"]
        .iter()
        .flat_map(|name| std::env::split_paths(&path).map(move |dir| dir.join(name)))
        .find(|p| p.is_file())
}

/// Chromium, or why a test cannot run: where `PVTC_REQUIRE_CHROMIUM` is set (`.ci/run`
/// sets it), its absence fails the test instead.
pub fn required() -> Result<PathBuf, String> {
    if let Some(binary) = find() {
        return Ok(binary);
    }
    let why = "chromium is not installed (apt-get install chromium)".to_string();
    if std::env::var_os("PVTC_REQUIRE_CHROMIUM").is_some() {
        panic!("{why}, and PVTC_REQUIRE_CHROMIUM is set");
    }
    Err(why)
}

/// A running Chromium with one page attached.
pub struct Browser {
    child: Child,
    to: std::fs::File,
    from: Receiver<Value>,
    next: u64,
    session: String,
    /// Every event seen so far, in order.
    pub events: Vec<Value>,
    dir: PathBuf,
}

impl Browser {
    /// Starts `binary` with a fresh profile and opens a page of `width` × `height`.
    pub fn start(binary: &Path, width: u32, height: u32) -> Browser {
        let dir = std::env::temp_dir().join(format!(
            "pvtc-chromium-{}-{:?}",
            std::process::id(),
            std::thread::current().id()
        ));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("profile")).unwrap();
        let (input, output) = (dir.join("in"), dir.join("out"));
        for fifo in [&input, &output] {
            let made = Command::new("mkfifo").arg(fifo).status().unwrap();
            assert!(made.success(), "mkfifo {}", fifo.display());
        }
        let profile = format!("--user-data-dir={}", dir.join("profile").display());
        let child = Command::new("sh")
            .arg("-c")
            .arg("exec \"$0\" \"$@\" 3<\"$PVTC_IN\" 4>\"$PVTC_OUT\"")
            .arg(binary)
            .args(FLAGS)
            .arg(profile)
            .arg("about:blank")
            .env("PVTC_IN", &input)
            .env("PVTC_OUT", &output)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("chromium starts");
        let to = std::fs::OpenOptions::new()
            .write(true)
            .open(&input)
            .unwrap();
        let reading = std::fs::File::open(&output).unwrap();
        let (send, from) = channel();
        std::thread::spawn(move || {
            let mut reader = BufReader::new(reading);
            let mut message = Vec::new();
            while reader.read_until(0, &mut message).is_ok_and(|n| n > 0) {
                message.pop();
                if let Ok(value) = serde_json::from_slice::<Value>(&message) {
                    if send.send(value).is_err() {
                        break;
                    }
                }
                message.clear();
            }
        });
        let mut browser = Browser {
            child,
            to,
            from,
            next: 0,
            session: String::new(),
            events: Vec::new(),
            dir,
        };
        let target = browser.browser_call("Target.createTarget", json!({"url": "about:blank"}));
        let id = target["targetId"].as_str().unwrap().to_string();
        let attached = browser.browser_call(
            "Target.attachToTarget",
            json!({"targetId": id, "flatten": true}),
        );
        browser.session = attached["sessionId"].as_str().unwrap().to_string();
        for domain in [
            "Runtime.enable",
            "Log.enable",
            "Network.enable",
            "Page.enable",
        ] {
            browser.call(domain, json!({}));
        }
        browser.call(
            "Emulation.setDeviceMetricsOverride",
            json!({"width": width, "height": height, "deviceScaleFactor": 1, "mobile": false}),
        );
        browser
    }

    fn send(&mut self, method: &str, params: Value, session: bool) -> Value {
        self.next += 1;
        let id = self.next;
        let mut message = json!({"id": id, "method": method, "params": params});
        if session {
            message["sessionId"] = json!(self.session);
        }
        let mut bytes = serde_json::to_vec(&message).unwrap();
        bytes.push(0);
        self.to.write_all(&bytes).unwrap();
        self.to.flush().unwrap();
        let deadline = Instant::now() + Duration::from_secs(120);
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.from.recv_timeout(left) {
                Ok(reply) if reply["id"] == json!(id) => {
                    assert!(reply.get("error").is_none(), "{method}: {reply}");
                    return reply["result"].clone();
                }
                Ok(event) => self.events.push(event),
                Err(RecvTimeoutError::Timeout) => panic!("{method}: no reply in 120 s"),
                Err(RecvTimeoutError::Disconnected) => panic!("{method}: chromium went away"),
            }
        }
    }

    fn browser_call(&mut self, method: &str, params: Value) -> Value {
        self.send(method, params, false)
    }

    /// Calls `method` on the page and returns its result, keeping the events meanwhile.
    pub fn call(&mut self, method: &str, params: Value) -> Value {
        self.send(method, params, true)
    }

    /// Evaluates `expression` in the page (awaiting a promise) and returns its value.
    pub fn evaluate(&mut self, expression: &str) -> Value {
        let result = self.call(
            "Runtime.evaluate",
            json!({"expression": expression, "awaitPromise": true, "returnByValue": true}),
        );
        assert!(
            result.get("exceptionDetails").is_none(),
            "{expression}: {result}"
        );
        result["result"]["value"].clone()
    }

    /// Waits (at most two minutes) for an event of `method` after the first `after`
    /// events, keeping the events meanwhile.
    pub fn wait_for(&mut self, method: &str, after: usize) {
        let deadline = Instant::now() + Duration::from_secs(120);
        while !self.events[after.min(self.events.len())..]
            .iter()
            .any(|e| e["method"] == method)
        {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.from.recv_timeout(left) {
                Ok(event) => self.events.push(event),
                Err(_) => panic!("no {method} in 120 s"),
            }
        }
    }

    /// Opens `url` and waits for its load event.
    pub fn open(&mut self, url: &str) {
        let before = self.events.len();
        self.call("Page.navigate", json!({"url": url}));
        self.wait_for("Page.loadEventFired", before);
    }

    /// The events seen of `method`.
    pub fn seen(&self, method: &str) -> Vec<&Value> {
        self.events
            .iter()
            .filter(|e| e["method"] == method)
            .collect()
    }

    /// The processor time of the browser and all its processes so far, seconds (user and
    /// system, from /proc at 100 ticks a second): what the page cost, whatever else the
    /// machine runs meanwhile.
    pub fn cpu_seconds(&self) -> f64 {
        let stats: Vec<(u32, u32, u64)> = std::fs::read_dir("/proc")
            .into_iter()
            .flatten()
            .flatten()
            .filter_map(|e| {
                let pid: u32 = e.file_name().to_str()?.parse().ok()?;
                let stat = std::fs::read_to_string(e.path().join("stat")).ok()?;
                // After the command's closing parenthesis: state, ppid, … utime (14), stime (15).
                let fields: Vec<&str> = stat.rsplit_once(')')?.1.split_whitespace().collect();
                let ppid = fields.get(1)?.parse().ok()?;
                let ticks =
                    fields.get(11)?.parse::<u64>().ok()? + fields.get(12)?.parse::<u64>().ok()?;
                Some((pid, ppid, ticks))
            })
            .collect();
        let mut family = vec![self.child.id()];
        let mut i = 0;
        while i < family.len() {
            let parent = family[i];
            family.extend(stats.iter().filter(|s| s.1 == parent).map(|s| s.0));
            i += 1;
        }
        let ticks: u64 = stats
            .iter()
            .filter(|s| family.contains(&s.0))
            .map(|s| s.2)
            .sum();
        ticks as f64 / 100.0
    }

    /// A PNG screenshot of the page.
    pub fn screenshot(&mut self) -> Vec<u8> {
        let shot = self.call("Page.captureScreenshot", json!({"format": "png"}));
        decode_base64(shot["data"].as_str().unwrap())
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        // Asked to close, it ends its own processes; killed only if it does not.
        let close = format!(
            "{{\"id\": {}, \"method\": \"Browser.close\"}}\0",
            self.next + 1
        );
        let _ = self.to.write_all(close.as_bytes());
        let deadline = Instant::now() + Duration::from_secs(10);
        while Instant::now() < deadline {
            if let Ok(Some(_)) = self.child.try_wait() {
                let _ = std::fs::remove_dir_all(&self.dir);
                return;
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// Standard base64 to bytes (the protocol's screenshots).
fn decode_base64(text: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        _ => 63,
    };
    let (mut out, mut acc, mut bits) = (Vec::new(), 0u32, 0);
    for c in text.bytes().filter(|c| *c != b'=') {
        acc = (acc << 6) | u32::from(value(c));
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
        }
    }
    out
}
