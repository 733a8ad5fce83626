// The last scan and drawing the user opened, kept in this browser so a
// reload reopens them (the settings are in localStorage). IndexedDB keeps
// the File itself, so a large scan is stored once, by the browser, without
// being read here. Every failure (no IndexedDB, quota, private mode) only
// means the inputs are not kept.
const DB_NAME = 'pcpp';
const STORE = 'inputs';

function openDb() {
  return new Promise((ok, fail) => {
    if (typeof indexedDB === 'undefined') {
      fail(new Error('this browser keeps no files (no IndexedDB)'));
      return;
    }
    const req = indexedDB.open(DB_NAME, 1);
    req.onupgradeneeded = () => req.result.createObjectStore(STORE);
    req.onsuccess = () => ok(req.result);
    req.onerror = () => fail(req.error);
  });
}

async function inStore(mode, fn) {
  const db = await openDb();
  try {
    return await new Promise((ok, fail) => {
      const t = db.transaction(STORE, mode);
      const req = fn(t.objectStore(STORE));
      t.oncomplete = () => ok(req.result);
      t.onerror = () => fail(t.error);
      t.onabort = () => fail(t.error || new Error('the browser did not keep the file'));
    });
  } finally {
    db.close();
  }
}

// Keeps `value` ({name, file} for a scan, {name, bytes} for a drawing) as
// the last `kind` ('scan' or 'svg'); null forgets it.
export function keepInput(kind, value) {
  return inStore('readwrite', (s) => (value ? s.put(value, kind) : s.delete(kind)));
}

// The kept `kind`, or undefined.
export function keptInput(kind) {
  return inStore('readonly', (s) => s.get(kind));
}
