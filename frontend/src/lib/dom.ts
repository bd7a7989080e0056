/** Minimal DOM construction: the UI is plain TypeScript, no framework, so the bundle stays small. */

type Child = Node | string | number | null | undefined | false | Child[];
type Attrs = Record<string, unknown>;

/**
 * Create an element. Attributes starting with "on" become listeners, `class`/`text`/`dataset`/`style`
 * are handled specially, `true` sets a boolean attribute and `false`/`null`/`undefined` omits it.
 */
export function h<K extends keyof HTMLElementTagNameMap>(
  tag: K,
  attrs: Attrs | null = null,
  ...children: Child[]
): HTMLElementTagNameMap[K] {
  const element = document.createElement(tag);
  if (attrs) {
    for (const [key, value] of Object.entries(attrs)) {
      if (value === false || value === null || value === undefined) continue;
      if (key.startsWith("on") && typeof value === "function") {
        element.addEventListener(key.slice(2).toLowerCase(), value as EventListener);
      } else if (key === "class") {
        element.className = String(value);
      } else if (key === "text") {
        element.textContent = String(value);
      } else if (key === "dataset") {
        Object.assign(element.dataset, value as Record<string, string>);
      } else if (key === "style" && typeof value === "object") {
        Object.assign(element.style, value);
      } else if (key === "value" && "value" in element) {
        (element as HTMLInputElement).value = String(value);
      } else if (value === true) {
        element.setAttribute(key, "");
      } else {
        element.setAttribute(key, String(value));
      }
    }
  }
  append(element, children);
  return element;
}

function append(parent: Node, children: Child[]): void {
  for (const child of children) {
    if (child === null || child === undefined || child === false) continue;
    if (Array.isArray(child)) append(parent, child);
    else parent.appendChild(typeof child === "object" ? child : document.createTextNode(String(child)));
  }
}

/** Replace all children of `parent`. */
export function replaceChildren(parent: Element, ...children: Child[]): void {
  parent.textContent = "";
  append(parent, children);
}
