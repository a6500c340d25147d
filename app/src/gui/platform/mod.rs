//! What differs between the desktop app and the app in a web page (issue #59), in one place: a
//! newcomer sees here which code is the desktop's only and what the page has instead. Everything
//! else (the model, the sessions, the panels, the 3D view) is one code for both.
//!
//! | service | desktop | page (`wasm32`) |
//! |---|---|---|
//! | clock | std's `Instant` | the page's `performance.now()` — both as `web_time::Instant` |
//! | threads | a thread per background job, the frames stepped while the window paints, rayon's pool, a thread per reference computation (`readout.rs`) | none ([`HAS_THREADS`]): a job runs at once, in place; rayon runs on the calling thread; a reference is computed by a Web Worker (`page::reference_in_worker`) |
//! | storage | eframe's persistence: a file in the user's data folder | eframe's persistence: the browser's local storage |
//! | files | the Open dialog's typed paths, figures saved to a folder | a mesh file dropped into the page ([`dropped_files`]); no figure export |
//! | Rerun | the live link, a recording file, serving browsers (`rerun_link.rs`, `serve_web.rs`) | absent (`page::Rerun` refuses with a message) |
//! | start | `hox app`'s options, a native window (`launch.rs`) | the link's query (`args.rs`), the page's canvas (`launch.rs`) |

#[cfg(target_arch = "wasm32")]
pub mod page;

/// Whether background work may run on threads of its own (not in a page: wasm32 without
/// shared memory has one thread).
pub const HAS_THREADS: bool = cfg!(not(target_arch = "wasm32"));

/// A file dropped onto the window: its name and its bytes, or why they could not be read.
pub type Dropped = (String, Result<std::sync::Arc<[u8]>, String>);

/// The files dropped onto the window. On the desktop their bytes are read at once; a page reads
/// them asynchronously, so there they come with a later frame (the page asks for one).
pub fn dropped_files(ctx: &eframe::egui::Context) -> Vec<Dropped> {
    let files = ctx.input(|i| i.raw.dropped_files.clone());
    let name_of = |f: &eframe::egui::DroppedFileHandle| {
        f.path().file_name().map_or_else(|| f.path().display().to_string(), |n| n.to_string_lossy().into_owned())
    };
    #[cfg(not(target_arch = "wasm32"))]
    {
        files.iter().map(|f| (name_of(f), f.bytes().map(std::sync::Arc::from))).collect()
    }
    #[cfg(target_arch = "wasm32")]
    {
        for f in files {
            let (name, ctx) = (name_of(&f), ctx.clone());
            wasm_bindgen_futures::spawn_local(async move {
                let bytes = f.bytes_async().await.map(std::sync::Arc::from);
                page::INBOX.with(|inbox| inbox.borrow_mut().push((name, bytes)));
                ctx.request_repaint();
            });
        }
        page::INBOX.with(|inbox| std::mem::take(&mut *inbox.borrow_mut()))
    }
}
