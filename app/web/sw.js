// hox's service worker for the Rerun web viewer it serves (app/build.rs): it caches nothing, so
// a student's browser always loads the viewer and the data from the teacher's machine.
self.addEventListener("install", () => self.skipWaiting());
self.addEventListener("activate", (event) => event.waitUntil(self.clients.claim()));
