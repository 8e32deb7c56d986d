// Typesets what pymdownx.arithmatex (generic mode) writes: <span class="arithmatex">\(...\)</span> inline and
// <div class="arithmatex">\[...\]</div> as a block, with the KaTeX copy in assets/katex/ (the site builds and
// reads offline). Only those elements are touched, so a "$" elsewhere on a page stays text.
(function () {
  function typeset(root) {
    root.querySelectorAll(".arithmatex").forEach(function (el) {
      if (el.dataset.typeset) return;
      var tex = el.textContent.trim();
      var display = el.tagName === "DIV";
      tex = tex.replace(/^\\[(\[]/, "").replace(/\\[)\]]$/, "");
      try {
        katex.render(tex, el, { displayMode: display, throwOnError: false });
        el.dataset.typeset = "1";
      } catch (err) {
        console.warn("KaTeX:", err, tex);
      }
    });
  }
  if (typeof document$ !== "undefined") {
    document$.subscribe(function (doc) { typeset(doc.body || document.body); });
  } else {
    document.addEventListener("DOMContentLoaded", function () { typeset(document.body); });
  }
})();
