/**
 * DOM construction with reactive bindings, on the pattern of VanJS: a page holds its state in small `State`
 * values and binds them to attributes and children when it builds its elements; changing `state.val` updates
 * exactly the bound places. No virtual DOM, no re-render calls, no framework: the whole binding is this file.
 *
 * - `state(v)` — a value that tells its readers when it changes.
 * - `derive(fn)` — a state computed from others; re-computed when one of the states `fn` read changes.
 * - `effect(fn)` — run `fn` now and whenever a state it read changes; returns a function that stops it.
 * - `h(tag, attrs, ...children)` — an element; an attribute value or a child may be a `State` or a function
 *   (`() => value`), which binds it: the attribute or the child node follows the states the function read.
 *
 * - `untrack(fn)` — run `fn` without making the states it reads dependencies of the caller.
 * - `batch(fn)` — set several states; their readers run once, when `fn` returns.
 *
 * Ownership: bindings, effects and derived states created while a `Scope` runs (`scope.run(fn)`,
 * `scope.effect(fn)`) are stopped by its `dispose` — a page builds its element in its scope and disposes it in
 * `dispose`. A bound child owns what its content creates: when the content is replaced, the bindings of the
 * old content stop at once. Bindings also hold their DOM node weakly, so those made outside any scope stop once
 * their element is dropped and collected.
 */

export type Child = Node | string | number | null | undefined | false | Child[];
export type Bindable<T> = T | State<T> | (() => T);
type Attrs = Record<string, unknown>;

type Listener = () => void;

/** The reader currently being tracked: every state read while it runs becomes one of its dependencies. */
let tracking: Set<StateImpl<unknown>> | null = null;
/** The scope that owns the bindings, effects and derived states created now (see `Scope.run`). */
let owner: Scope | null = null;
/** Inside `batch`: readers to run when the outermost batch ends, in the order they were first notified. */
let batchDepth = 0;
const pending = new Set<Listener>();

export interface State<T> {
  val: T;
  /** The value without registering the reader as a dependency. */
  readonly rawVal: T;
}

class StateImpl<T> implements State<T> {
  private current: T;
  readonly listeners = new Set<Listener>();

  constructor(initial: T) {
    this.current = initial;
  }

  get val(): T {
    tracking?.add(this as StateImpl<unknown>);
    return this.current;
  }

  set val(next: T) {
    if (Object.is(next, this.current)) return;
    this.current = next;
    if (batchDepth > 0) for (const listener of this.listeners) pending.add(listener);
    else for (const listener of [...this.listeners]) listener();
  }

  get rawVal(): T {
    return this.current;
  }
}

export function state<T>(initial: T): State<T> {
  return new StateImpl(initial);
}

export function isState(value: unknown): value is State<unknown> {
  return value instanceof StateImpl;
}

/**
 * Run `compute` tracking the states it reads, and call `changed` (once per change) when one of them changes;
 * dependencies are re-collected on every run, so a branch not taken costs nothing. Returns the stop function.
 */
function track<T>(compute: () => T, changed: (value: T) => void): { first: T; stop: () => void } {
  let sources = new Set<StateImpl<unknown>>();
  let stopped = false;
  const run = (): T => {
    const previous = tracking;
    const reads = new Set<StateImpl<unknown>>();
    tracking = reads;
    try {
      return compute();
    } finally {
      tracking = previous;
      for (const source of sources) if (!reads.has(source)) source.listeners.delete(listener);
      for (const source of reads) source.listeners.add(listener);
      sources = reads;
    }
  };
  const listener = () => {
    if (stopped) return;
    // A re-run belongs to no scope: what it creates is owned by its own bound child, if any.
    const previousOwner = owner;
    owner = null;
    try {
      changed(run());
    } finally {
      owner = previousOwner;
    }
  };
  const stop = () => {
    stopped = true;
    for (const source of sources) source.listeners.delete(listener);
    sources.clear();
  };
  return { first: run(), stop };
}

/** A state computed from other states. */
export function derive<T>(compute: () => T): State<T> {
  let derived: StateImpl<T> | null = null;
  const { first, stop } = track(compute, (value) => {
    if (derived) derived.val = value;
  });
  owner?.add(stop);
  derived = new StateImpl(first);
  return derived;
}

/** Run `fn` now and again whenever a state it read changes, until the returned function is called. */
export function effect(fn: () => void): () => void {
  const { stop } = track(fn, () => undefined);
  owner?.add(stop);
  return stop;
}

/** Run `fn` without tracking: the states it reads do not become dependencies of the binding that calls it. */
export function untrack<T>(fn: () => T): T {
  const previous = tracking;
  tracking = null;
  try {
    return fn();
  } finally {
    tracking = previous;
  }
}

/** Run `fn`, which sets several states; each reader of them runs once, after `fn`, instead of once per change. */
export function batch<T>(fn: () => T): T {
  batchDepth += 1;
  try {
    return fn();
  } finally {
    batchDepth -= 1;
    if (batchDepth === 0) {
      while (pending.size > 0) {
        const listeners = [...pending];
        pending.clear();
        for (const listener of listeners) listener();
      }
    }
  }
}

/**
 * Stops of the bindings, effects and subscriptions that end together — with a page (`dispose`), a bound child's
 * content, or a set of rows.
 */
export class Scope {
  private readonly stops: (() => void)[] = [];

  /** Run `fn` with this scope as the owner of the bindings, effects and derived states it creates. */
  run<T>(fn: () => T): T {
    const previous = owner;
    // The owner is module state by design (what `h` creates registers in it), not an alias for `this`.
    // eslint-disable-next-line @typescript-eslint/no-this-alias
    owner = this;
    try {
      return fn();
    } finally {
      owner = previous;
    }
  }

  effect(fn: () => void): void {
    this.run(() => effect(fn));
  }

  /** Register any other clean-up (an interval, a socket, a hub subscription). */
  add(stop: () => void): void {
    this.stops.push(stop);
  }

  dispose(): void {
    for (const stop of this.stops.splice(0)) stop();
  }
}

/** The current value of a bindable, tracked when read inside a binding. */
export function valueOf<T>(value: Bindable<T>): T {
  if (isState(value)) return (value as State<T>).val;
  if (typeof value === "function") return (value as () => T)();
  return value;
}

/**
 * Bind `read` to `node`: `apply` runs now and on every change while `node` is alive (held weakly, so a
 * dropped page's bindings end with its elements) and until the owning scope is disposed.
 */
function bind<T>(node: Node, read: () => T, apply: (target: Node, value: T) => void, onStop?: () => void): void {
  const ref = new WeakRef(node);
  const { first, stop } = track(read, (value) => {
    const target = ref.deref();
    if (target) apply(target, value);
    else end();
  });
  const end = () => {
    stop();
    onStop?.();
  };
  owner?.add(end);
  apply(node, first);
}

function isBound(value: unknown): value is State<unknown> | (() => unknown) {
  return isState(value) || typeof value === "function";
}

function setAttribute(element: HTMLElement, key: string, value: unknown): void {
  if (key === "class") element.className = value === false || value == null ? "" : String(value);
  else if (key === "text") element.textContent = value == null ? "" : String(value);
  else if (key === "value" && "value" in element) (element as HTMLInputElement).value = value == null ? "" : String(value);
  else if ((key === "checked" || key === "disabled" || key === "hidden") && key in element)
    (element as unknown as Record<string, boolean>)[key] = Boolean(value);
  else if (value === false || value === null || value === undefined) element.removeAttribute(key);
  else element.setAttribute(key, value === true ? "" : String(value));
}

function applyAttribute(element: HTMLElement, key: string, value: unknown): void {
  if (key.startsWith("on") && typeof value === "function") {
    element.addEventListener(key.slice(2).toLowerCase(), value as EventListener);
  } else if (key === "dataset") {
    Object.assign(element.dataset, value as Record<string, string>);
  } else if (key === "style" && typeof value === "object" && value !== null) {
    Object.assign(element.style, value);
  } else if (isBound(value)) {
    bind(element, () => valueOf(value), (target, current) => setAttribute(target as HTMLElement, key, current));
  } else if (value !== false && value !== null && value !== undefined) {
    setAttribute(element, key, value);
  }
}

/**
 * Create an element. Attributes starting with "on" become listeners; `class`, `text`, `value`, `checked`,
 * `disabled`, `hidden` set the property; `dataset`/`style` objects are merged; `true` sets a boolean attribute,
 * `false`/`null`/`undefined` omits it. Any other value that is a `State` or a function is bound.
 */
export function h<K extends keyof HTMLElementTagNameMap>(
  tag: K,
  attrs: Attrs | null = null,
  ...children: (Child | Bindable<Child>)[]
): HTMLElementTagNameMap[K] {
  const element = document.createElement(tag);
  if (attrs) for (const [key, value] of Object.entries(attrs)) if (key !== "value") applyAttribute(element, key, value);
  append(element, children);
  // After the children: a <select>'s value can only pick one of its options once they are there.
  if (attrs && "value" in attrs) applyAttribute(element, "value", attrs.value);
  return element;
}

function toNodes(child: Child): Node[] {
  if (child === null || child === undefined || child === false) return [];
  if (Array.isArray(child)) return child.flatMap(toNodes);
  return [typeof child === "object" ? child : document.createTextNode(String(child))];
}

/**
 * A bound child: the nodes between two empty text markers are replaced whenever the states read by `read`
 * change (a list, an optional part, a text). Each content is built in its own scope, disposed when the content
 * is replaced. Both markers are held weakly (a strong reference to one would keep the whole element alive).
 */
function boundChild(read: () => Child): DocumentFragment {
  const start = document.createTextNode("");
  const end = document.createTextNode("");
  const endRef = new WeakRef(end);
  const fragment = document.createDocumentFragment();
  fragment.append(start, end);
  let content: Scope | null = null;
  const build = (): Child => {
    content?.dispose();
    content = new Scope();
    return content.run(read);
  };
  bind(start, build, (marker, child) => {
    const parent = marker.parentNode;
    const last = endRef.deref();
    if (!parent || !last) return;
    while (marker.nextSibling && marker.nextSibling !== last) parent.removeChild(marker.nextSibling);
    for (const node of toNodes(child)) parent.insertBefore(node, last);
  }, () => content?.dispose());
  return fragment;
}

function append(parent: Node, children: (Child | Bindable<Child>)[]): void {
  for (const child of children) {
    if (isBound(child)) parent.appendChild(boundChild(() => valueOf(child) as Child));
    else if (Array.isArray(child)) append(parent, child);
    else for (const node of toNodes(child as Child)) parent.appendChild(node);
  }
}

/** Replace all children of `parent`. */
export function replaceChildren(parent: Element, ...children: (Child | Bindable<Child>)[]): void {
  parent.textContent = "";
  append(parent, children);
}
