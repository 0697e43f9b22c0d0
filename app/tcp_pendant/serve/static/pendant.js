/* TCP Pendant's own page script (served at /tcp-pendant/pendant.js by tcp_pendant/serve/client_script.py).
 *
 * A static file: no server state, request or user text is ever written into it. It only reads the
 * page's DOM and clicks viser's own GUI buttons, so the server sees exactly what a mouse click
 * sends (no new server API). User text (a trainee's name, a trainer token) is only ever put into
 * an input's .value, never into HTML.
 *
 * 1. Keyboard shortcuts (ignored while typing in a text field, with Ctrl/Alt/Meta held, or while
 *    a dialog such as the welcome window is open; a checkbox, button, dropdown or slider that
 *    kept the focus after a click does not swallow them):
 *      1..6          jog + on jog-key row 1..6 (X Y Z A B C; in Joint mode the joints A1..A6)
 *      Shift+1..6    jog - on that row
 *      [  ]          next smaller / larger increment (the Increment row, toward 0.1 / Cont.)
 *      R, Enter      Record: the running wizard's step, else "Record point" (Enter only when no
 *                    button or field has the focus)
 *      N             the running wizard's Next (Finish on its last step)
 *      B             the running wizard's Back
 *    Incremental mode: one step per key press (a held key does not repeat, as on a pendant).
 *    Cont. mode: the key is held like the mouse button on a hold-to-jog key (press, release).
 *    viser's own keys (W A S D Q E, the arrows: camera; Space) are not used.
 * 2. "Your name" is remembered in this browser's localStorage once the class accepted it, and
 *    typed and submitted again when a new welcome window appears (reload, reconnect, server
 *    restart), with the browser key the server issued at the join: the server hands a new key
 *    over in a hidden <div data-tcp-pendant-key="KEY"> (letters, digits, - and _ only; kept in
 *    localStorage), and the script types it into the "Browser key" field (whose row it hides) of
 *    each welcome window, so the server knows it is the same browser. A welcome window holding
 *    <div data-tcp-pendant-hold> is not joined by the script (the name went to another tab of
 *    this browser: no tug of war); one holding <div data-tcp-pendant-forget> (the trainer
 *    released the name) also makes it forget the name and key.
 * 3. /?trainer=TOKEN: the token is taken from the address, dropped from the address bar at once
 *    (history.replaceState) and typed into "Trainer token" + "Open trainer view" of each welcome
 *    window of this page (kept in memory only, for reconnects). Only a page opened as /?trainer
 *    (with or without a token: then the trainer types it) shows the "Trainer token" row, "Open
 *    trainer view" and the welcome window's "Trainer: open ..." line; a trainee's page hides them.
 * 4. Pinned folders: the trainer's message to a trainee (the folder holding class
 *    "trainer-message", views/class_notices.py: in view on whatever tab, however far the trainee
 *    scrolled) and, in presenter mode, the folder holding the readout (class "presenter-readout",
 *    which only views/presenter.py writes), the message's first, are pinned at the top of the
 *    panel while the panel scrolls
 *    (position: sticky; viser 1.1 has no sticky GUI element). Its ancestors up to the panel's
 *    scroll area that clip with overflow: hidden are set to overflow: clip, which clips the same
 *    but is no scroll container (a sticky element sticks to its nearest scroll container), with
 *    min-width 0 (a clipping flex item would otherwise grow with its content, and the error
 *    chart, which takes its container's width, would grow without end); the scroll area itself
 *    no longer scrolls sideways (what those ancestors cut off stays cut off).
 * 5. Software WebGL: in a browser whose WebGL renderer is a software one (its name, as
 *    WEBGL_debug_renderer_info gives it, says SwiftShader, llvmpipe, softpipe, software or Basic
 *    Render: no graphics card), the "Shadows" checkbox is clicked off once each time the server
 *    shows one: the shadow maps would cost such a browser most of each frame. A trainee may tick
 *    it again. The --shared pendant's "Shadows (every screen)" is left alone. The checkbox gets
 *    data-tcp-pendant-shadows="off" or "kept" (a hardware renderer), what the script decided.
 * 6. Screens (one constant style sheet, STYLE): the tip views (the image labelled "Tip close-up",
 *    views/tip_insets.py) float over the 3D view's lower left corner (a phone's: its upper
 *    left), so the step, its Record and the jog keys fit the panel beside them at 1024x768; on a
 *    device whose pointer is coarse (a touch screen) every button is at least 44 CSS px tall
 *    and the "Keys: ..." line is hidden (no keyboard); on a phone the panel's bottom sheet is at
 *    most 38 % of the screen high, so the reference tip (the 3D view's centre) stays in view.
 * 7. Touch and hold-to-jog: a held jog key is a lease the server lets run out 250 ms after the
 *    browser's last renewal (pendant/hold.py). The script makes sure every hold ends in the
 *    release click the server waits for (a touch the browser cancels, a long press it turns
 *    into a context menu, or a lost pointer capture sends none of its own) and keeps the
 *    browser from panning or selecting while a jog key is held.
 * 8. The connection after a server restart. viser's client asks its websocket worker for a new
 *    attempt every second while it is disconnected, and the worker closes the attempt still
 *    opening when the next one comes: a server that needs more than a second to answer the
 *    handshake (just restarted, restoring every trainee's calibration, answering the other pages
 *    rejoining) never gets one finished, each socket closes before it opened (code 1006), for
 *    minutes; and viser asks for no attempt at all while the window has no focus (a projector's
 *    page, a trainee in another window). The script wraps the page's Worker constructor and, for
 *    viser's websocket worker only (the one told "set_server"), drops viser's own retries and
 *    sends one of its own after each failed attempt: never while one is opening (the worker
 *    gives an attempt 5 s), 0.5 s after the first failure, then every second, focus or not.
 *    Once down for LOST_MS it shows, in words, that the server cannot be reached, with a
 *    "Reload the page" button (it keeps trying meanwhile; the notice goes at the next
 *    connection). <html> gets data-tcp-pendant-connection="connected" / "reconnecting" / "lost"
 *    and data-tcp-pendant-connections (how many times the page connected).
 * 9. The math board (presenter mode's "Math board", views/math_board_view.py): while the page
 *    holds the server's <div class="math-board"> (our own escaped markup), a copy of its nodes
 *    (cloneNode: no HTML parsed here) covers the whole page, with a "Back to the pendant" button
 *    that unticks "Math board" (as a click on it would); the original is hidden in the panel.
 *    Both words come in the pendant's language from the board's data-toggle and data-back
 *    attributes (calibrate/math_board.py), English when they are absent.
 * 10. Languages: the labels this script looks for (Increment, its "Cont." button, Shadows, the keys
 *     line's first word, the tip views' caption's first words, Record point, the wizard's
 *     Record, Next, Finish and Back) and the words it writes itself (the lost-connection notice and
 *     its "Reload the page" button, the tooltips "Key R", "Key N", "Key B") are read in the
 *     pendant's language from the hidden <div data-tcp-pendant-labels data-increment=... data-cont=...
 *     data-shadows=... data-keys-line=... data-tip-views=... data-record-point=... data-record=...
 *     data-next=... data-finish=... data-back=... data-lost=... data-reload=... data-key-r=...
 *     data-key-n=... data-key-b=...> below the keys line (views/pendant_panel.py), and the welcome window's (Your name, Browser key, Join the
 *     class, Trainer token, Open trainer view, the trainer line's and the banner's first word)
 *     from its own <div data-tcp-pendant-labels data-name=... data-join=...> (views/identity.py);
 *     English when they are absent. The jog keys' labels
 *     ("X +", "A1 −") are the same in every language.
 */
(function () {
  "use strict";
  if (window.__tcpPendantScript) return;
  window.__tcpPendantScript = true;

  var MINUS = "\u2212";
  var MARK = "\u2713";
  var L = {
    name: "Your name", key: "Browser key", join: "Join the class", token: "Trainer token",
    openTrainer: "Open trainer view", trainerLine: "Trainer: open",
    increment: "Increment", record: "Record", recordPoint: "Record point", banner: "Trainee:",
    shadows: "Shadows", next: "Next \u25b6", finish: "Finish \u25b6", back: "\u25c0 Back",
    keysLine: "Keys:", tipViews: "Tip close-up", cont: "Cont.",
    lost: "This page cannot reach the pendant server (it is still trying). " +
      "Your name and your recorded touches are kept on the server: reload the page to join again.",
    reload: "Reload the page", keyR: "Key R", keyN: "Key N", keyB: "Key B"
  };
  var SOFTWARE_RE = /swiftshader|llvmpipe|softpipe|software|basic render/i;
  var CARTESIAN = ["X", "Y", "Z", "A", "B", "C"];
  var NAME_KEY = "tcpPendant.traineeName";
  var BROWSER_KEY = "tcpPendant.browserKey";
  var KEY_RE = /^[A-Za-z0-9_-]{20,200}$/;
  var MAX_TEXT = 200;
  var SETTLE_MS = 400;          // viser sends a field's value in its own message slot: wait before the click
  var JOG_RE = /^(.+) ([\u2212+])$/;

  // ------------------------------------------------------------------ the DOM
  function text(el) { return (el && el.textContent || "").trim(); }
  function laidOut(el) { return el.getClientRects().length > 0; }   // not in a hidden tab
  function allButtons() { return Array.prototype.slice.call(document.querySelectorAll("button")); }
  function buttonsNamed(name) { return allButtons().filter(function (b) { return text(b) === name; }); }
  function pick(list) {                     // enabled, the one on show first
    var ok = list.filter(function (b) { return !b.disabled; });
    return ok.filter(laidOut)[0] || ok[0] || null;
  }
  function labelled(name) {                 // the row (label + control) of viser's input labelled `name`
    var labels = document.querySelectorAll("label");
    for (var i = 0; i < labels.length; i++) {
      if (text(labels[i]) !== name) continue;
      var row = labels[i];
      while (row && !row.querySelector("input, textarea, button")) row = row.parentElement;
      if (row) return row;
    }
    return null;
  }
  var LABEL_KEYS = { "increment": "increment", "cont": "cont", "shadows": "shadows", "keys-line": "keysLine",
    "name": "name", "key": "key", "join": "join", "token": "token", "open-trainer": "openTrainer",
    "trainer-line": "trainerLine", "banner": "banner", "tip-views": "tipViews", "record-point": "recordPoint",
    "record": "record", "next": "next", "finish": "finish", "back": "back", "lost": "lost", "reload": "reload",
    "key-r": "keyR", "key-n": "keyN", "key-b": "keyB" };
  function label(key) {                     // a label in the session's language (views/pendant_panel.py and
    var el = document.querySelector("[data-tcp-pendant-labels][data-" + key + "]");   // views/identity.py
    var v = el && el.getAttribute("data-" + key);                                    // hand them over)
    return v || L[LABEL_KEYS[key]];                                                  // else English
  }
  function field(name) { var row = labelled(name); return row ? row.querySelector("input, textarea") : null; }
  var NOT_TEXT = /^(checkbox|radio|range|button|submit|reset|color|file|image)$/i;
  function editable(el) {                   // a text field: the keys type into it
    if (!el || el.nodeType !== 1) return false;
    if (el.isContentEditable) return true;
    var tag = el.tagName;
    if (el.getAttribute("aria-haspopup") === "listbox" && el.getAttribute("aria-expanded") !== "true") {
      return false;                         // a dropdown, closed: its field is no text to type
    }
    return tag === "TEXTAREA" || (tag === "INPUT" && !el.readOnly && !el.disabled && !NOT_TEXT.test(el.type || ""));
  }
  function interactive(el) {
    return !!(el && el.nodeType === 1 && el !== document.body &&
      (editable(el) || el.closest("button, a, input, select, textarea, [role=button], [role=tab], [role=slider], " +
                                  "[role=option], [role=checkbox], [tabindex]")));
  }
  function dialogOpen() {
    var d = document.querySelectorAll(".mantine-Modal-content, [role=dialog][aria-modal=true]");
    for (var i = 0; i < d.length; i++) if (laidOut(d[i])) return true;
    return false;
  }
  function typeInto(input, value) {         // React listens for the native setter + an input event
    var proto = input.tagName === "TEXTAREA" ? HTMLTextAreaElement.prototype : HTMLInputElement.prototype;
    Object.getOwnPropertyDescriptor(proto, "value").set.call(input, value);
    input.dispatchEvent(new Event("input", { bubbles: true }));
  }

  // ------------------------------------------------------------------ 6. the connection
  var RETRY_MS = [500, 1000];               // the wait after the 1st, then every failed attempt
  var LOST_MS = 15000;                      // down this long: say so, offer a reload
  var conn = { worker: null, post: null, opening: false, up: false, failures: 0, downSince: 0,
               timer: null, lostTimer: null, connections: 0 };
  function connState(state) {
    var root = document.documentElement;
    root.setAttribute("data-tcp-pendant-connection", state);
    root.setAttribute("data-tcp-pendant-connections", String(conn.connections));
  }
  function attempt() {                      // one attempt, only when none is opening
    conn.timer = null;
    if (!conn.worker || conn.up || conn.opening) return;
    conn.opening = true;
    conn.post.call(conn.worker, { type: "retry" });
  }
  function lostNotice(show) {
    var box = document.getElementById("tcp-pendant-lost");
    if (!show) { if (box) box.remove(); return; }
    if (box || !document.body) return;
    box = document.createElement("div");
    box.id = "tcp-pendant-lost";
    box.setAttribute("role", "alert");
    box.style.cssText = "position:fixed;top:12px;left:50%;transform:translateX(-50%);z-index:10000;" +
      "max-width:min(560px,92vw);padding:14px 18px;border-radius:8px;background:#fff4e5;color:#5f3700;" +
      "border:2px solid #e8590c;box-shadow:0 4px 16px rgba(0,0,0,.3);font:16px/1.4 sans-serif";
    var p = document.createElement("p");
    p.style.margin = "0 0 10px 0";
    p.textContent = label("lost");
    var b = document.createElement("button");
    b.type = "button";
    b.textContent = label("reload");
    b.style.cssText = "font:600 16px sans-serif;padding:6px 14px;border-radius:6px;border:0;" +
      "background:#e8590c;color:#fff;cursor:pointer";
    b.addEventListener("click", function () { window.location.reload(); });
    box.appendChild(p);
    box.appendChild(b);
    document.body.appendChild(box);
  }
  function onConnected() {
    conn.up = true; conn.opening = false; conn.failures = 0; conn.downSince = 0;
    conn.connections += 1;
    if (conn.timer !== null) { window.clearTimeout(conn.timer); conn.timer = null; }
    if (conn.lostTimer !== null) { window.clearTimeout(conn.lostTimer); conn.lostTimer = null; }
    lostNotice(false);
    connState("connected");
  }
  function onClosed() {
    conn.up = false; conn.opening = false;
    if (!conn.downSince) {
      conn.downSince = Date.now();
      conn.lostTimer = window.setTimeout(function () {
        conn.lostTimer = null;
        if (!conn.up && conn.worker) { lostNotice(true); connState("lost"); }
      }, LOST_MS);
    }
    if (document.getElementById("tcp-pendant-lost") === null) connState("reconnecting");
    var wait = RETRY_MS[Math.min(conn.failures, RETRY_MS.length - 1)];
    conn.failures += 1;
    if (conn.timer === null) conn.timer = window.setTimeout(attempt, wait);
  }
  function watchWorker(w) {
    var post = w.postMessage;
    w.postMessage = function (data) {
      var type = data && typeof data === "object" ? data.type : null;
      if (type === "set_server") {          // viser's websocket worker: its first attempt
        conn.worker = w; conn.post = post; conn.opening = true; conn.up = false;
      } else if (conn.worker === w && type === "retry") {
        return undefined;                   // ours instead (attempt)
      } else if (conn.worker === w && type === "close") {
        conn.worker = null;
        if (conn.timer !== null) { window.clearTimeout(conn.timer); conn.timer = null; }
      }
      return post.apply(w, arguments);
    };
    w.addEventListener("message", function (e) {
      var d = e.data;
      if (conn.worker !== w || !d || typeof d !== "object") return;
      if (d.type === "connected") onConnected();
      else if (d.type === "closed") onClosed();
    });
  }
  (function wrapWorker() {
    var Native = window.Worker;
    if (typeof Native !== "function") return;
    function PendantWorker(url, options) {
      var w = arguments.length > 1 ? new Native(url, options) : new Native(url);
      try { watchWorker(w); } catch (err) { /* the page works as viser's alone */ }
      return w;
    }
    PendantWorker.prototype = Native.prototype;
    window.Worker = PendantWorker;
  })();

  // ------------------------------------------------------------------ 1. keys
  function jogRows() {
    var rows = [], byName = {};
    allButtons().forEach(function (b) {
      var m = JOG_RE.exec(text(b));
      if (!m) return;
      var row = byName[m[1]];
      if (!row) { row = byName[m[1]] = { name: m[1], minus: null, plus: null }; rows.push(row); }
      if (m[2] === "+") row.plus = row.plus || b; else row.minus = row.minus || b;
    });
    rows = rows.filter(function (r) { return r.minus && r.plus; });
    var cart = CARTESIAN.map(function (n) { return byName[n]; });
    if (cart.every(function (r) { return r && r.minus && r.plus; })) return cart;   // X..C in that order
    return rows;                                                                     // joints, in page order
  }

  function incrementButtons() {
    var row = labelled(label("increment"));
    return row ? Array.prototype.slice.call(row.querySelectorAll("button")) : [];
  }
  var pendingIncrement = null;              // {index, at}: clicked, the server's mark not yet back
  function stepIncrement(direction) {       // +1: smaller (to the right), -1: larger (toward Cont.)
    var bs = incrementButtons();
    if (!bs.length) return;
    var marked = -1;
    bs.forEach(function (b, i) { if (text(b).indexOf(MARK) === 0) marked = i; });
    var base = marked;
    if (pendingIncrement && pendingIncrement.index !== marked && Date.now() - pendingIncrement.at < 1500) {
      base = pendingIncrement.index;
    }
    if (base < 0) return;
    var next = Math.max(0, Math.min(bs.length - 1, base + direction));
    if (next === base || bs[next].disabled) return;
    pendingIncrement = { index: next, at: Date.now() };
    bs[next].click();
  }

  function continuous() {
    var selected = incrementButtons().filter(function (b) { return text(b).indexOf(MARK) === 0; })[0];
    return !!selected && text(selected).indexOf(label("cont")) >= 0;
  }

  function step(names) {                    // the wizard's Next / Finish or Back (the one on show)
    var list = [];
    names.forEach(function (n) { list = list.concat(buttonsNamed(n)); });
    var b = pick(list.filter(laidOut));
    if (b) b.click();
  }

  function record() {
    var free = buttonsNamed(label("record-point"));         // shown outside a wizard only
    var b = free.length ? pick(free) : pick(buttonsNamed(label("record")));
    if (b) b.click();
  }

  var held = {};                            // key code -> the hold-to-jog button it holds
  function pointer(type, b) {
    b.dispatchEvent(new PointerEvent(type, {
      bubbles: true, cancelable: true, composed: true, button: 0, buttons: type === "pointerdown" ? 1 : 0,
      pointerId: 1, pointerType: "mouse", isPrimary: true
    }));
  }
  function hold(code, b) {
    releaseAll();
    held[code] = b;
    pointer("pointerdown", b);
  }
  function release(code) {
    var b = held[code];
    if (!b) return;
    delete held[code];
    pointer("pointerup", b);
    if (b.isConnected) b.click();           // the release click: the server stops at once
  }
  function releaseAll() { Object.keys(held).forEach(release); }

  function jog(index, sign, code) {
    var row = jogRows()[index];
    if (!row) return;
    var b = sign > 0 ? row.plus : row.minus;
    if (b.disabled) return;
    if (b.id && continuous()) {
      hold(code, b);                        // a single hold-to-jog button (Cont.)
    } else {
      b.click();
    }
  }

  function onKeyDown(e) {
    if (e.defaultPrevented || e.ctrlKey || e.altKey || e.metaKey || e.isComposing) return;
    if (editable(e.target) || editable(document.activeElement) || dialogOpen()) return;
    var digit = /^(?:Digit|Numpad)([1-9])$/.exec(e.code || "");
    var key = e.key || "";
    if (digit) {
      e.preventDefault();
      if (!e.repeat) jog(Number(digit[1]) - 1, e.shiftKey ? -1 : 1, e.code);
    } else if (key === "[" || key === "]") {
      e.preventDefault();
      if (!e.repeat) stepIncrement(key === "[" ? 1 : -1);
    } else if (key === "r" || key === "R" || (key === "Enter" && !interactive(e.target))) {
      e.preventDefault();
      if (!e.repeat) record();
    } else if (key === "n" || key === "N") {
      e.preventDefault();
      if (!e.repeat) step([label("next"), label("finish")]);
    } else if (key === "b" || key === "B") {
      e.preventDefault();
      if (!e.repeat) step([label("back")]);
    }
  }
  document.addEventListener("keydown", onKeyDown);
  document.addEventListener("keyup", function (e) { release(e.code); });
  window.addEventListener("blur", releaseAll);
  document.addEventListener("visibilitychange", function () { if (document.hidden) releaseAll(); });

  // ------------------------------------------------------------------ 7. a hold ends in a release
  function holdKey(el) {                    // the hold-to-jog key (a single button) under el
    var b = el && el.closest ? el.closest("button") : null;
    return b && b.id && JOG_RE.test(text(b)) ? b : null;
  }
  var pressed = null;                       // {button, clicked}: a hold-to-jog key held by a pointer
  function endHold(cancelled) {
    var p = pressed;
    if (!p) return;
    pressed = null;
    if (cancelled) { if (p.button.isConnected) p.button.click(); return; }
    window.setTimeout(function () {         // the browser's own click comes right after pointerup
      if (!p.clicked && p.button.isConnected) p.button.click();
    }, 60);
  }
  document.addEventListener("pointerdown", function (e) {
    var b = holdKey(e.target);
    if (b && e.isTrusted) pressed = { button: b, clicked: false };
  }, true);
  document.addEventListener("click", function (e) {
    if (pressed && holdKey(e.target) === pressed.button) pressed.clicked = true;
  }, true);
  document.addEventListener("pointerup", function (e) { if (e.isTrusted) endHold(false); }, true);
  document.addEventListener("pointercancel", function () { endHold(true); }, true);
  document.addEventListener("contextmenu", function (e) {        // a long press: no menu, no lost release
    if (holdKey(e.target) || (e.target && e.target.closest && e.target.closest("[data-tcp-pendant-touch]"))) {
      e.preventDefault();
    }
  }, true);
  window.addEventListener("blur", function () { endHold(true); });

  // ------------------------------------------------------------------ 3. the trainer URL
  var trainerToken = null;
  var trainerPage = false;                  // opened as /?trainer: the welcome window's trainer rows show
  try {
    var url = new URL(window.location.href);
    if (url.searchParams.has("trainer")) {
      trainerPage = true;
      var t = url.searchParams.get("trainer") || "";
      url.searchParams.delete("trainer");
      window.history.replaceState(window.history.state, "", url.pathname + url.search + url.hash);
      if (t.length > 0 && t.length <= MAX_TEXT) trainerToken = t;
    }
  } catch (err) { /* no URL API: the typed token still works */ }

  // ------------------------------------------------------------------ 2. the name
  function storage() { try { return window.localStorage; } catch (err) { return null; } }
  function storedName() {
    var s = storage();
    try {
      var v = s && s.getItem(NAME_KEY);
      return typeof v === "string" && v.trim().length > 0 && v.length <= MAX_TEXT ? v : null;
    } catch (err) { return null; }
  }
  function rememberName(v) {
    var s = storage();
    try { if (s && v.trim().length > 0 && v.length <= MAX_TEXT) s.setItem(NAME_KEY, v); } catch (err) { /* full */ }
  }
  function storedKey() {
    var s = storage();
    try {
      var v = s && s.getItem(BROWSER_KEY);
      return typeof v === "string" && KEY_RE.test(v) ? v : null;
    } catch (err) { return null; }
  }
  function rememberKey(v) {
    var s = storage();
    try { if (s && KEY_RE.test(v)) s.setItem(BROWSER_KEY, v); } catch (err) { /* full */ }
  }
  function forgetAll() {
    var s = storage();
    try { if (s) { s.removeItem(NAME_KEY); s.removeItem(BROWSER_KEY); } } catch (err) { /* nothing kept */ }
  }

  var joining = null;                       // {value, input, at}: "Join the class" clicked, not yet accepted
  document.addEventListener("click", function (e) {
    var b = e.target && e.target.closest ? e.target.closest("button") : null;
    if (!b || text(b) !== label("join")) return;
    var input = field(label("name"));
    if (input) joining = { value: String(input.value), input: input, at: Date.now() };
  }, true);

  function bannerShown() {                  // "Trainee: NAME" appears once the server took the name
    var ps = document.querySelectorAll("p, div, span");
    for (var i = 0; i < ps.length; i++) {
      if (ps[i].children.length <= 2 && text(ps[i]).indexOf(label("banner")) === 0) return true;
    }
    return false;
  }

  var tried = typeof WeakSet === "function" ? new WeakSet() : null;
  function once(input) {                    // each welcome window is filled at most once
    if (!tried || tried.has(input)) return false;
    tried.add(input);
    return true;
  }
  function fillAndPress(input, value, buttonName, keyInput, key) {
    typeInto(input, value);
    if (keyInput && key) typeInto(keyInput, key);
    window.setTimeout(function () {
      if (!input.isConnected) return;
      var b = pick(buttonsNamed(buttonName));
      if (b) b.click();
    }, SETTLE_MS);
  }

  var seen = typeof WeakSet === "function" ? new WeakSet() : null;
  function first(el) {                      // each marker element is acted on once
    if (!el || !seen || seen.has(el)) return false;
    seen.add(el);
    return true;
  }

  function browserKey() {                   // a key the server handed over: keep it
    var el = document.querySelector("[data-tcp-pendant-key]");
    if (!first(el)) return;
    var k = el.getAttribute("data-tcp-pendant-key") || "";
    if (KEY_RE.test(k)) rememberKey(k);
  }

  function hide(el) { if (el && el.style.display !== "none") el.style.display = "none"; }
  function hideTrainerRows() {              // the token row, its button and the trainer's line
    hide(labelled(label("token")));
    buttonsNamed(label("open-trainer")).forEach(hide);
    var ps = document.querySelectorAll("p");
    for (var i = 0; i < ps.length; i++) if (text(ps[i]).indexOf(label("trainer-line")) === 0) hide(ps[i]);
  }

  function scan() {
    browserKey();
    var forget = document.querySelector("[data-tcp-pendant-forget]");
    if (first(forget)) { forgetAll(); joining = null; }
    var keyRow = labelled(label("key"));
    if (keyRow && keyRow.style.display !== "none") keyRow.style.display = "none";   // the script's own field
    if (!trainerPage) hideTrainerRows();    // a trainee's welcome window: no trainer token
    if (!joining && !trainerToken && storedName() === null && storedKey() === null) return;
    if (joining && !joining.input.isConnected) {
      if (bannerShown()) { rememberName(joining.value); joining = null; }
      else if (Date.now() - joining.at > 30000) joining = null;
    }
    var tokenInput = trainerToken ? field(label("token")) : null;
    if (tokenInput) {
      if (once(tokenInput)) fillAndPress(tokenInput, trainerToken, label("open-trainer"));
      return;                               // the trainer's page: no trainee name
    }
    var nameInput = field(label("name"));
    if (!nameInput || !once(nameInput)) return;
    var keyInput = field(label("key"));
    var key = storedKey();
    var held = document.querySelector("[data-tcp-pendant-hold], [data-tcp-pendant-forget]");
    var name = storedName();
    if (held || name === null) {            // no join by the script: the key still goes with a typed name
      if (keyInput && key) typeInto(keyInput, key);
      return;
    }
    fillAndPress(nameInput, name, label("join"), keyInput, key);
  }

  // viser 1.1 shows the hint of a button group as a tooltip, not a single button's: name the key
  // in the native tooltip (a constant text) of the single jog, hold-to-jog and Record buttons
  function setTitle(b, title) { if (b && b.id && b.getAttribute("title") !== title) b.setAttribute("title", title); }
  function keyTitles() {
    jogRows().forEach(function (r, i) {
      if (i >= 9) return;
      setTitle(r.plus, "Key " + (i + 1));
      setTitle(r.minus, "Key Shift+" + (i + 1));
    });
    buttonsNamed(label("record")).concat(buttonsNamed(label("record-point"))).forEach(function (b) { setTitle(b, label("key-r")); });
    buttonsNamed(label("next")).concat(buttonsNamed(label("finish"))).forEach(function (b) { setTitle(b, label("key-n")); });
    buttonsNamed(label("back")).forEach(function (b) { setTitle(b, label("key-b")); });
  }

  // the trainer's message (class "trainer-message", views/class_notices.py) above the presenter's
  // readout (class "presenter-readout", views/presenter.py): each one's folder pinned, one under the other
  var PIN_CLASSES = ["trainer-message", "presenter-readout"];
  function pinFolder(folder, top) {
    var viewport = folder.closest(".mantine-ScrollArea-viewport");
    if (!viewport) return false;
    if (folder.getAttribute("data-tcp-pendant-pinned") !== "1") {
      for (var e = folder.parentElement; e && e !== viewport; e = e.parentElement) {
        var ov = getComputedStyle(e).overflowY;
        if (ov === "hidden" || ov === "auto" || ov === "scroll") {
          e.style.overflow = "clip";
          e.style.minWidth = "0";           // as a scroll container's: a flex item no wider than its box
        }
      }
      viewport.style.overflowX = "hidden";   // what the clipping ancestors cut off stays cut off
      folder.style.position = "sticky";
      folder.style.zIndex = "5";
      folder.style.background = "var(--mantine-color-body, #fff)";
      // an opaque band over the 10 px above it, and a shadow below: the panel goes on under it
      folder.style.boxShadow = "0 -12px 0 0 var(--mantine-color-body, #fff), 0 4px 6px -4px rgba(0, 0, 0, 0.35)";
      folder.setAttribute("data-tcp-pendant-pinned", "1");
    }
    var px = top + "px";
    if (folder.style.top !== px) folder.style.top = px;   // the folder's title sits on its top border
    return true;
  }
  function pinPresenter() {
    var top = 10;
    PIN_CLASSES.forEach(function (cls) {
      var marker = document.querySelector("." + cls);
      var folder = marker && marker.closest(".mantine-Paper-root");
      if (folder && laidOut(folder) && pinFolder(folder, top)) top += folder.getBoundingClientRect().height + 12;
    });
  }

  // ------------------------------------------------------------------ 7. the math board
  var BOARD_CLASS = "math-board";
  var BOARD_ID = "tcp-pendant-board";
  var BOARD_TOGGLE = "Math board";
  function boardSource() {
    var all = document.querySelectorAll("." + BOARD_CLASS);
    for (var i = 0; i < all.length; i++) if (!all[i].closest("#" + BOARD_ID)) return all[i];
    return null;
  }
  function boardWord(attr, english) {        // the board's words in the pendant's language
    var source = boardSource();             // (calibrate/math_board.py hands them over), else English
    return (source && source.getAttribute(attr)) || english;
  }
  function leaveBoard() {
    var row = labelled(boardWord("data-toggle", BOARD_TOGGLE));
    var box = row ? row.querySelector("input[type=checkbox]") : null;
    if (box && box.checked) box.click();     // the server unticks it: the board goes for every screen
  }
  function board() {
    var source = boardSource();
    var overlay = document.getElementById(BOARD_ID);
    if (!source) { if (overlay) overlay.remove(); return; }
    if (source.style.display !== "none") source.style.display = "none";   // shown once, full screen
    if (!overlay) {
      overlay = document.createElement("div");
      overlay.id = BOARD_ID;
      overlay.style.cssText = "position:fixed;inset:0;z-index:9000;background:#fff;color:#111;" +
        "padding:10px 16px;box-sizing:border-box;overflow:hidden";
      var back = document.createElement("button");
      back.type = "button";
      back.textContent = "Back to the pendant";
      back.style.cssText = "position:absolute;top:8px;right:12px;z-index:1;font:600 15px sans-serif;" +
        "padding:4px 12px;border-radius:6px;border:1px solid #888;background:#f4f4f4;cursor:pointer";
      back.addEventListener("click", leaveBoard);
      overlay.appendChild(back);
      overlay.appendChild(document.createElement("div"));
      document.body.appendChild(overlay);
    }
    var backButton = overlay.firstChild, backWord = boardWord("data-back", "Back to the pendant");
    if (backButton.textContent !== backWord) backButton.textContent = backWord;
    var holder = overlay.lastChild;
    var copy = source.cloneNode(true);       // our own markup, copied as nodes (no HTML parsed)
    copy.style.display = "";
    if (!holder.firstChild || !holder.firstChild.isEqualNode(copy)) {
      while (holder.firstChild) holder.removeChild(holder.firstChild);
      holder.appendChild(copy);
    }
  }

  // ------------------------------------------------------------------ 5. software WebGL
  var software = null;                      // the renderer's verdict, asked once
  function softwareWebgl() {
    if (software === null) {
      software = false;
      try {
        var canvas = document.createElement("canvas");
        var gl = canvas.getContext("webgl2") || canvas.getContext("webgl");
        var info = gl && gl.getExtension("WEBGL_debug_renderer_info");
        if (info) software = SOFTWARE_RE.test(String(gl.getParameter(info.UNMASKED_RENDERER_WEBGL) || ""));
        var lose = gl && gl.getExtension("WEBGL_lose_context");
        if (lose) lose.loseContext();       // the probe's context is not kept
      } catch (e) { software = false; }
    }
    return software;
  }
  function shadowsOff() {
    var row = labelled(label("shadows"));
    var box = row ? row.querySelector("input[type=checkbox]") : null;
    if (!box || !first(box)) return;
    var off = softwareWebgl();
    box.setAttribute("data-tcp-pendant-shadows", off ? "off" : "kept");   // what the script decided
    if (off && box.checked) box.click();
  }

  // ------------------------------------------------------------------ 6. screens
  var TIP_W = 344;                          // the tip views' image, px wide (2 x 168 + 8)
  var STYLE = [
    "[data-tcp-pendant-tipviews] { position: fixed !important; left: 12px; bottom: 12px; z-index: 30;",
    "  width: calc(" + TIP_W + "px + 2 * var(--mantine-spacing-xs, 10px)); max-width: calc(100vw - 24px); box-sizing: border-box; padding-top: 6px; padding-bottom: 4px;",
    "  background: rgba(255, 255, 255, 0.94); border-radius: 6px; box-shadow: 0 1px 6px rgba(0, 0, 0, 0.3); }",
    "[data-tcp-pendant-tipviews] p { font-size: 12px !important; line-height: 1.3; margin-bottom: 2px; }",
    "@media (max-width: 600px) {",
    "  [data-tcp-pendant-tipviews] { top: 8px; bottom: auto; left: 8px; width: min(" + (TIP_W + 20) + "px, 62vw); padding-top: 3px; }",
    "  [data-tcp-pendant-tipviews] p { font-size: 10px !important; }",
    "  .mantine-Paper-root[style*='position: fixed'][style*='bottom: 0px'] { max-height: 38% !important; }",
    "}",
    "[data-tcp-pendant-touch] { touch-action: none; user-select: none; -webkit-user-select: none; -webkit-touch-callout: none; }",
    "@media (pointer: coarse) {",
    "  .mantine-Button-root { height: auto !important; min-height: 44px !important; }",
    "  [data-tcp-pendant-keys-line] { display: none !important; }",
    "}"
  ].join("\n");
  function styleSheet() {
    if (document.getElementById("tcp-pendant-style")) return;
    var el = document.createElement("style");
    el.id = "tcp-pendant-style";
    el.textContent = STYLE;                 // a constant: nothing from the server or the user
    (document.head || document.documentElement).appendChild(el);
  }
  function guiRow(el) {                     // the wrapper viser puts around one GUI element
    var row = el;
    while (row && row.parentElement && row.parentElement.children.length === 1 &&
           !row.parentElement.classList.contains("mantine-Tabs-panel")) row = row.parentElement;
    return row;
  }
  function markScreens() {
    allButtons().forEach(function (b) {     // the keys a finger holds: no pan, no selection, no menu
      var t = text(b);
      if ((JOG_RE.test(t) || t === label("record") || t === label("record-point")) && !b.hasAttribute("data-tcp-pendant-touch")) {
        b.setAttribute("data-tcp-pendant-touch", "1");
      }
    });
    var ps = document.querySelectorAll("p");
    for (var i = 0; i < ps.length; i++) {
      if (text(ps[i]).indexOf(label("keys-line")) !== 0) continue;
      var line = guiRow(ps[i]);
      if (line && !line.hasAttribute("data-tcp-pendant-keys-line")) line.setAttribute("data-tcp-pendant-keys-line", "1");
    }
    var imgs = document.querySelectorAll("img");
    for (var j = 0; j < imgs.length; j++) {
      var box = imgs[j].parentElement && imgs[j].parentElement.parentElement;   // label + image (viser's image)
      if (!box || box.hasAttribute("data-tcp-pendant-tipviews")) continue;
      if (text(box).indexOf(label("tip-views")) >= 0) box.setAttribute("data-tcp-pendant-tipviews", "1");
    }
  }

  var scheduled = false;
  function schedule() {
    if (scheduled) return;
    scheduled = true;
    window.setTimeout(function () {
      scheduled = false;
      keyTitles();
      markScreens();
      pinPresenter();
      board();
      shadowsOff();
      scan();
    }, 150);
  }
  function start() {
    new MutationObserver(schedule).observe(document.documentElement, { childList: true, subtree: true });
    styleSheet();
    document.documentElement.setAttribute("data-tcp-pendant-script", "1");
    schedule();
  }
  if (document.readyState === "loading") document.addEventListener("DOMContentLoaded", start); else start();
})();
