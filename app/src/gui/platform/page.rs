//! The page's stand-ins for what only the desktop has (issue #59): Rerun's live link, recording
//! file and serving browsers need sockets, files and threads a page does not give. The app keeps
//! its Rerun section; asking for a link there answers with a message instead of a panic.
//!
//! And what only the page has: its address (for *Copy link*) and the app's state published on
//! the page (`window.hox_state`, JSON) for the page's tests and scripts.

thread_local! {
    /// Dropped files whose bytes the page has read, waiting for the next frame
    /// ([`super::dropped_files`]).
    pub static INBOX: std::cell::RefCell<Vec<super::Dropped>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Publishes `state` as `window.hox_state` (a JSON string: `JSON.parse(window.hox_state)`).
pub fn publish_state(state: &serde_json::Value) {
    if let Some(window) = web_sys::window() {
        let _ = js_sys::Reflect::set(&window, &"hox_state".into(), &state.to_string().into());
    }
}

/// The page's address without its query (`http://host:port/`), to which a link's query is put.
pub fn page_address() -> Option<String> {
    let location = web_sys::window()?.location();
    Some(format!("{}{}", location.origin().ok()?, location.pathname().ok()?))
}

/// In a page: no Rerun output. Same interface as the desktop's (`rerun_link::Rerun`).
pub struct Rerun {
    serve: crate::web::ServeArgs,
}

/// What the page says when a Rerun output is asked for.
pub const NO_RERUN: &str = "Rerun needs the desktop app (`hox app`): a web page cannot open a socket or write a file";

impl Rerun {
    pub fn new(serve: crate::web::ServeArgs, _serve_fps: u32) -> Rerun {
        Rerun { serve }
    }

    /// Asked to start: the message that it cannot; asked to stop: nothing to say.
    pub fn set<T, M>(&mut self, target: Option<T>, _model: &M, _url: &str, _file: &str) -> Option<String> {
        target.map(|_| NO_RERUN.to_string())
    }

    pub fn is_open(&self) -> bool {
        false
    }

    pub fn target(&self) -> Option<&str> {
        None
    }

    pub fn web_url(&self) -> Option<&str> {
        None
    }

    pub fn bind(&self) -> String {
        self.serve.bind.to_string()
    }

    pub fn log<M>(&mut self, _model: &M) -> Option<String> {
        None
    }

    pub fn flush<M>(&mut self, _model: &M) -> Option<String> {
        None
    }
}

/// A reference computed by a Web Worker of its own (`worker.js`: a second instance of the page's
/// module, so the page keeps drawing and playing meanwhile, as the desktop's thread does);
/// dropping it terminates the worker, which is how a computation no session wants any more
/// stops (the desktop's stops at its next progress report).
pub struct WorkerJob {
    worker: web_sys::Worker,
    _on_message: wasm_bindgen::closure::Closure<dyn FnMut(web_sys::MessageEvent)>,
    _on_error: wasm_bindgen::closure::Closure<dyn FnMut(web_sys::ErrorEvent)>,
}

impl Drop for WorkerJob {
    fn drop(&mut self) {
        self.worker.terminate();
    }
}

// SAFETY: a page's module runs on one thread (wasm32 without shared memory): nothing of a
// WorkerJob is ever reached from another thread; it sits in the app's `Sync` job list only.
unsafe impl Send for WorkerJob {}
// SAFETY: as above.
unsafe impl Sync for WorkerJob {}

/// What a reference's worker reports.
pub enum WorkerEvent {
    /// What it does and how far, 0–1.
    Progress(String, f64),
    /// A provisional estimate (JSON of `hox_scenes::reference::Reference`).
    Estimate(String),
    /// The reference (JSON), or why there is none.
    Done(Result<String, String>),
}

/// Starts a worker computing the reference `request` asks for (`compute_reference`'s JSON); its
/// reports go to `on_event` as they come, between the page's frames.
pub fn reference_in_worker(
    request: &serde_json::Value,
    on_event: impl Fn(WorkerEvent) + 'static,
) -> Result<WorkerJob, String> {
    use wasm_bindgen::JsCast;
    use wasm_bindgen::closure::Closure;
    let options = web_sys::WorkerOptions::new();
    options.set_type(web_sys::WorkerType::Module);
    let worker = web_sys::Worker::new_with_options("./worker.js", &options)
        .map_err(|e| format!("cannot start the reference's worker: {e:?}"))?;
    let on_event = std::rc::Rc::new(on_event);
    let on = on_event.clone();
    let on_message = Closure::<dyn FnMut(web_sys::MessageEvent)>::new(move |e: web_sys::MessageEvent| {
        let text = e.data().as_string().unwrap_or_default();
        let Ok(m) = serde_json::from_str::<serde_json::Value>(&text) else { return };
        let event = if let Some([what, fraction]) = m.get("progress").and_then(|p| p.as_array()).map(Vec::as_slice) {
            WorkerEvent::Progress(what.as_str().unwrap_or_default().to_string(), fraction.as_f64().unwrap_or(0.0))
        } else if let Some(r) = m.get("estimate").and_then(|r| r.as_str()) {
            WorkerEvent::Estimate(r.to_string())
        } else if let Some(r) = m.get("result").and_then(|r| r.as_str()) {
            WorkerEvent::Done(Ok(r.to_string()))
        } else {
            WorkerEvent::Done(Err(m.get("error").and_then(|e| e.as_str()).unwrap_or("no reference").to_string()))
        };
        on(event);
    });
    let on_error = Closure::<dyn FnMut(web_sys::ErrorEvent)>::new(move |e: web_sys::ErrorEvent| {
        on_event(WorkerEvent::Done(Err(format!("the reference's worker stopped: {}", e.message()))));
    });
    worker.set_onmessage(Some(on_message.as_ref().unchecked_ref()));
    worker.set_onerror(Some(on_error.as_ref().unchecked_ref()));
    worker
        .post_message(&request.to_string().into())
        .map_err(|e| format!("cannot hand the reference to its worker: {e:?}"))?;
    Ok(WorkerJob { worker, _on_message: on_message, _on_error: on_error })
}

/// The worker's side (`worker.js` calls it): the reference of the scene in `request`
/// (`{"scene": TOML, "source", "with_field", "finest_cells"}`), its progress and provisional
/// estimates posted back through `post` as they come, then `{"result": JSON}` or
/// `{"error": message}`. The same computation as the desktop's thread (`readout.rs`).
#[wasm_bindgen::prelude::wasm_bindgen]
pub fn compute_reference(request: &str, post: &js_sys::Function) {
    use serde_json::json;
    let send = |v: serde_json::Value| {
        let _ = post.call1(&wasm_bindgen::JsValue::NULL, &v.to_string().into());
    };
    let result = (|| -> Result<String, String> {
        let r: serde_json::Value = serde_json::from_str(request).map_err(|e| e.to_string())?;
        let text = r["scene"].as_str().ok_or("no scene in the request")?;
        let scene =
            hox_scenes::Scene::from_toml(text, r["source"].as_str().unwrap_or("page")).map_err(|e| e.to_string())?;
        hox_scenes::reference::read_only_cache(site_reference);
        let lookup = hox_scenes::reference::Lookup {
            finest_cells: r["finest_cells"].as_u64().unwrap_or(hox_scenes::reference::FINEST_CELLS as u64) as usize,
            cache_dir: None,
        };
        let mut report = |what: &str, fraction: f64| send(json!({ "progress": [what, fraction] }));
        let mut on_estimate = |e: &hox_scenes::reference::Reference| {
            if let Ok(text) = serde_json::to_string(e) {
                send(json!({ "estimate": text }));
            }
        };
        let reference = lookup
            .get(&scene, r["with_field"].as_bool().unwrap_or(false), &mut report, &mut on_estimate)
            .map_err(|e| e.to_string())?;
        serde_json::to_string(&reference).map_err(|e| e.to_string())
    })();
    send(match result {
        Ok(r) => json!({ "result": r }),
        Err(e) => json!({ "error": e }),
    });
}

/// A reference cache file the site was built with (`references/NAME`, written by
/// `scripts/build-web.sh` from the desktop's computation of every lesson's references), read
/// synchronously, which a worker may do; None when the site has none.
fn site_reference(name: &str) -> Option<String> {
    let request = web_sys::XmlHttpRequest::new().ok()?;
    request.open_with_async("GET", &format!("references/{name}"), false).ok()?;
    request.send().ok()?;
    (request.status().ok()? == 200).then(|| request.response_text().ok().flatten()).flatten()
}

/// Milliseconds per simulated frame of the benchmark beam `label` (`hox bench`'s labels, e.g.
/// "P2 8x2x2", "P1 16x4x4 r1") in this page: one thread, the colour sweep, `hox bench`'s warm-up
/// frames, then the median of `frames` frames timed by the page's clock. JSON: the label, the
/// median, the register width of the batches, the frames. `scripts/web_speed.py` times it side by
/// side with the desktop's `hox bench --threads 1 --sweep colour` (docs/WEB.md).
#[wasm_bindgen::prelude::wasm_bindgen]
pub fn bench_beam(label: &str, frames: u32) -> Result<String, String> {
    use hox_scenes::bench::{CASES, WARMUP_FRAMES, bending_beam};
    let case = CASES.iter().find(|c| c.label() == label).ok_or_else(|| {
        format!("no benchmark beam '{label}': {}", CASES.iter().map(|c| c.label()).collect::<Vec<_>>().join(", "))
    })?;
    let mut sim = bending_beam(case, hox_sim::solver::Sweep::Colour).map_err(|e| e.to_string())?;
    for _ in 0..WARMUP_FRAMES {
        sim.step_frame().map_err(|e| e.to_string())?;
    }
    let mut times_ms = Vec::with_capacity(frames as usize);
    for _ in 0..frames.max(1) {
        let clock = web_time::Instant::now();
        sim.step_frame().map_err(|e| e.to_string())?;
        times_ms.push(clock.elapsed().as_secs_f64() * 1e3);
    }
    let ms_per_frame = hox_sim::measure::median(&mut times_ms);
    Ok(serde_json::json!({
        "label": label,
        "ms_per_frame": ms_per_frame,
        "lanes": sim.simd_lanes().first(),
        "frames": times_ms.len(),
    })
    .to_string())
}

/// Waits `ms` milliseconds, the page's event loop running meanwhile (a worker's messages, the
/// next frame).
pub async fn sleep_ms(ms: i32) {
    let promise = js_sys::Promise::new(&mut |resolve, _| {
        if let Some(w) = web_sys::window() {
            let _ = w.set_timeout_with_callback_and_timeout_and_arguments_0(&resolve, ms);
        }
    });
    let _ = wasm_bindgen_futures::JsFuture::from(promise).await;
}
