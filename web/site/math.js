// The course's formulas, typeset in the page by KaTeX (loaded before this file): the ```math
// blocks of the chapters, which `mirador book` (src/course/book.rs) made into
// <div class="math-display">. A formula KaTeX cannot read stays as its text, and the console says
// which (web/site-test.sh fails on it).
for (const element of document.querySelectorAll(".math-display")) {
  const tex = element.textContent;
  try {
    katex.render(tex, element, { displayMode: true, throwOnError: true });
  } catch (e) {
    element.textContent = tex;
    console.error(`a formula KaTeX cannot typeset: ${e.message}\n${tex}`);
  }
}
