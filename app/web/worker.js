// The page's reference computations (issue #59): a second instance of hox's module computes a
// reference off the page's thread, as the desktop app computes it on a thread of its own, and
// posts its progress, estimates and result back (gui/platform/page.rs). One worker per
// computation; the page terminates it when no configuration wants that reference any more.
import init, { compute_reference } from "./hox.js";

const ready = init();
onmessage = async (e) => {
    await ready;
    compute_reference(e.data, (message) => postMessage(message));
};
