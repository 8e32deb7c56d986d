// Typesets the formulas of the docstrings and pages: what pymdownx.arithmatex (generic mode) writes,
// <span class="arithmatex">\(...\)</span> inline and <div class="arithmatex">\[...\]</div> as a block, with the
// KaTeX copy in assets/katex/ (the site builds and reads offline). Only those elements are touched, so a "$"
// elsewhere on a page stays text.
//
// The docstrings write formulas between dollar signs in plain Unicode math that reads as it is in help()
// (docs/contributing.md, "Formulas"): `$u = V×n/|V×n|$`, `$z_near$`, `$√(x² + y²)$`, `$window_from_world$`.
// toTex() turns that into TeX before KaTeX sees it: a multi-letter name is upright (\mathrm), a name_sub gets its
// subscript (italic up to two letters, indices such as jk; upright from three, z_near), a snake_case name of
// three or more parts is one upright name, cos/sin/max/... are operators,
// √(...) a root, Unicode super- and subscripts TeX ones, <= and >= the relations. TeX written as TeX (a
// backslash command, braces) passes through. tests/test_docs.py runs every docstring formula through this
// function and KaTeX (node), so a formula that does not typeset fails the tests.
(function () {
  var OPERATORS = ["arccos", "arcsin", "arctan", "cos", "sin", "tan", "cot", "sec", "csc", "cosh", "sinh",
    "tanh", "exp", "log", "ln", "max", "min", "det", "sup", "inf", "lim", "arg", "deg", "dim", "gcd"];
  var RENAMED = { atan: "\\arctan", acos: "\\arccos", asin: "\\arcsin", atan2: "\\operatorname{atan2}",
    sqrt: "\\operatorname{sqrt}" };
  var SUPER = { "⁰": "0", "¹": "1", "²": "2", "³": "3", "⁴": "4", "⁵": "5", "⁶": "6", "⁷": "7", "⁸": "8",
    "⁹": "9", "⁺": "+", "⁻": "-", "ⁿ": "n", "ᵀ": "T" };
  var SUB = { "₀": "0", "₁": "1", "₂": "2", "₃": "3", "₄": "4", "₅": "5", "₆": "6", "₇": "7", "₈": "8",
    "₉": "9", "ᵢ": "i", "ⱼ": "j", "ₖ": "k", "ₙ": "n", "ₓ": "x" };
  var SYMBOLS = { "‖": "\\|", "…": "\\ldots ", "⋯": "\\cdots ", "∑": "\\sum ", "∏": "\\prod ", "∫": "\\int ",
    "∇": "\\nabla ", "∂": "\\partial ", "→": "\\to ", "←": "\\leftarrow ", "⇒": "\\Rightarrow ", "∘": "\\circ ",
    "⊗": "\\otimes ", "∧": "\\wedge ", "∨": "\\vee ", "⌊": "\\lfloor ", "⌋": "\\rfloor ", "⌈": "\\lceil ",
    "⌉": "\\rceil ", "⟨": "\\langle ", "⟩": "\\rangle ", "%": "\\%", "#": "\\#", "&": "\\&", "@": "\\mathbin{@}",
    "±": "\\pm ", "·": "\\cdot ", "½": "\\tfrac12", "⅓": "\\tfrac13", "¼": "\\tfrac14", "⌀": "\\varnothing ",
    "~": "\\mathord{\\sim}", "\u2AFD": "\\mathbin{/\\mkern-5mu/}", "⊙": "\\odot ", "∩": "\\cap ", "∪": "\\cup ",
    "¬": "\\lnot ", "⊥": "\\perp ", "∓": "\\mp ", "≪": "\\ll ", "≫": "\\gg ", "∝": "\\propto ", "≡": "\\equiv " };

  var ACCENTS = { "\u0302": "\\hat", "\u0307": "\\dot", "\u0308": "\\ddot", "\u0304": "\\bar",
    "\u0303": "\\tilde", "\u20D7": "\\vec" };

  function accent(out, command) {
    // the combining mark follows its letter: wrap the last emitted symbol
    var m = /(\\mathrm\{[^{}]*\}|\\[A-Za-z]+ ?|.)$/.exec(out);
    return out.slice(0, out.length - m[0].length) + command + "{" + m[0].trim() + "}";
  }

  function name(word) {
    if (word === "Σ") return "\\sum ";
    if (word === "Π") return "\\prod ";
    if (OPERATORS.indexOf(word) >= 0) return "\\" + word + " ";
    if (RENAMED[word]) return RENAMED[word] + " ";
    var m = /^([A-Za-z]+)([0-9]*)$/.exec(word);
    if (word.length === 1 || (m && m[1].length === 1)) return word;
    return "\\mathrm{" + word + "}";
  }

  function identifier(word) {
    var parts = word.split("_");
    if (parts.length === 1) return name(word);
    if (parts.length === 2 && parts[0] && parts[1]) {
      var sub = /^[0-9]+$/.test(parts[1]) || parts[1].length <= 2 ? parts[1] : "\\mathrm{" + parts[1] + "}";
      return name(parts[0]) + "_{" + sub + "}";
    }
    return "\\mathrm{" + word.replace(/_/g, "\\_") + "}";
  }

  function roots(s) {
    // √(...) with balanced parentheses, √x, √5
    var out = "";
    for (var i = 0; i < s.length; i++) {
      if (s[i] !== "√") { out += s[i]; continue; }
      if (s[i + 1] === "(") {
        var depth = 0, j = i + 1;
        for (; j < s.length; j++) {
          if (s[j] === "(") depth++;
          else if (s[j] === ")" && --depth === 0) break;
        }
        out += "\\sqrt{" + roots(s.slice(i + 2, j)) + "}";
        i = j;
      } else {
        var m = /^[A-Za-z0-9.]+/.exec(s.slice(i + 1)) || [""];
        out += "\\sqrt{" + m[0] + "}";
        i += m[0].length;
      }
    }
    return out;
  }

  function toTex(s) {
    s = s.normalize("NFD");  // â → a + combining ^, ẋ → x + combining dot
    s = s.replace(/<=/g, "≤").replace(/>=/g, "≥").replace(/!=/g, "≠").replace(/\/\//g, "\u2AFD");
    s = s.replace(/\*\*([A-Za-z0-9.]+|\([^()]*\))/g, function (m, e) { return "^{" + e.replace(/^\((.*)\)$/, "$1") + "}"; });
    // runs of Unicode super/subscripts
    s = s.replace(/[⁰¹²³⁴⁵⁶⁷⁸⁹⁺⁻ⁿᵀ]+/g, function (r) {
      return "^{" + r.split("").map(function (c) { return SUPER[c]; }).join("") + "}";
    });
    s = s.replace(/[₀₁₂₃₄₅₆₇₈₉ᵢⱼₖₙₓ]+/g, function (r) {
      return "_{" + r.split("").map(function (c) { return SUB[c]; }).join("") + "}";
    });
    s = roots(s);
    // x_(i+1) and x^(n-1): the parenthesised group is the script
    s = s.replace(/([_^])\(([^()]*)\)/g, "$1{$2}");
    var out = "";
    var re = /\\[A-Za-z]+|\\.|[A-Za-z][A-Za-z0-9]*(?:_[A-Za-z0-9]+)*|[\u0391-\u03A9\u03B1-\u03C9](?:_[A-Za-z0-9]+)*|[0-9.]+|\s+|[\s\S]/g;
    var m, word = false, space = false;
    while ((m = re.exec(s)) !== null) {
      var t = m[0];
      if (/^\s/.test(t)) {
        if (/^ {3,}$/.test(t) && out) out += "\\qquad ";  // "N' = …,   N = P_u × P_v": two formulas on one line
        space = true;
        continue;
      }
      var isWord = /^[A-Za-z0-9.]/.test(t);
      if (space && word && isWord) out += "\\ ";  // "depth at the pixel": words keep their spaces
      space = false;
      word = isWord;
      if (t[0] === "\\") out += t;
      else if (/^[A-Za-z\u0391-\u03A9\u03B1-\u03C9]/.test(t)) out += identifier(t);
      else if (ACCENTS[t]) out = accent(out, ACCENTS[t]);
      else if (SYMBOLS[t]) out += SYMBOLS[t];
      else out += t;
    }
    return out;
  }

  function typeset(root) {
    root.querySelectorAll(".arithmatex").forEach(function (el) {
      if (el.dataset.typeset) return;
      var tex = el.textContent.trim();
      var display = el.tagName === "DIV";
      tex = tex.replace(/^\\[(\[]/, "").replace(/\\[)\]]$/, "");
      try {
        katex.render(toTex(tex), el, { displayMode: display, throwOnError: false });
        el.dataset.typeset = "1";
      } catch (err) {
        console.warn("KaTeX:", err, tex);
      }
    });
  }

  if (typeof module !== "undefined" && module.exports) {
    module.exports = { toTex: toTex };  // node: the tests
    return;
  }
  if (typeof document$ !== "undefined") {
    document$.subscribe(function (doc) { typeset(doc.body || document.body); });
  } else {
    document.addEventListener("DOMContentLoaded", function () { typeset(document.body); });
  }
})();
