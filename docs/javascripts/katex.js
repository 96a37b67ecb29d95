// Typeset the mathematics that pymdownx.arithmatex (generic mode) leaves in the page:
// <span class="arithmatex">\( … \)</span> and <div class="arithmatex">\[ … \]</div>.
// KaTeX itself is vendored from the npm package `katex` by tools/vendor_katex.sh (no CDN).
// A formula KaTeX cannot parse is shown in red and reported with console.error, which the
// browser test (tests/test_browser.py) treats as a failure.
(function () {
  "use strict";
  function typeset(root) {
    if (typeof katex === "undefined") {
      console.error("KaTeX is not loaded: run tools/vendor_katex.sh before building the site");
      return;
    }
    root.querySelectorAll(".arithmatex").forEach(function (el) {
      if (el.dataset.typeset) { return; }
      var tex = el.textContent.trim();
      var display = el.tagName === "DIV";
      var m = /^\\[\(\[]([\s\S]*)\\[\)\]]$/.exec(tex);
      if (m) { tex = m[1]; }
      try {
        katex.render(tex, el, { displayMode: display, throwOnError: true, strict: "ignore" });
      } catch (err) {
        console.error("KaTeX could not typeset " + JSON.stringify(tex) + ": " + err.message);
        el.classList.add("katex-failed");
        katex.render(tex, el, { displayMode: display, throwOnError: false, strict: "ignore" });
      }
      el.dataset.typeset = "1";
    });
  }
  if (typeof document$ !== "undefined") {
    document$.subscribe(function () { typeset(document.body); });
  } else if (document.readyState === "loading") {
    document.addEventListener("DOMContentLoaded", function () { typeset(document.body); });
  } else {
    typeset(document.body);
  }
})();
