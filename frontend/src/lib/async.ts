/**
 * Asynchronous data as reactive states (`lib/dom.ts`): a page declares what it loads from which inputs, and binds
 * the answer; when an input changes the data is loaded again and only the latest answer is kept.
 */

import { state, type Scope, type State } from "./dom";

export type Loaded<T> =
  | { status: "loading" }
  | { status: "ready"; value: T }
  | { status: "failed"; error: unknown };

/**
 * Load `load(input())` now and again whenever a state read by `input` changes (until `scope` is disposed). An
 * answer that arrives after a newer request started is dropped, so a slow old answer never overwrites a new one.
 * `load` runs outside the tracking: the states it reads do not trigger a reload.
 */
export function loader<I, T>(scope: Scope, input: () => I, load: (input: I) => Promise<T>): State<Loaded<T>> {
  const result = state<Loaded<T>>({ status: "loading" });
  let latest = 0;
  scope.effect(() => {
    const request = input();
    const token = ++latest;
    result.val = { status: "loading" };
    void Promise.resolve()
      .then(() => load(request))
      .then(
        (value) => {
          if (token === latest) result.val = { status: "ready", value };
        },
        (error: unknown) => {
          if (token === latest) result.val = { status: "failed", error };
        },
      );
  });
  scope.add(() => (latest = -1));
  return result;
}

/** A copy of `source` that follows it once it stopped changing for `ms` (a search field's text). */
export function debounced<T>(scope: Scope, source: State<T>, ms: number): State<T> {
  const copy = state(source.rawVal);
  let timer: ReturnType<typeof setTimeout> | undefined;
  scope.effect(() => {
    const value = source.val;
    clearTimeout(timer);
    if (Object.is(value, copy.rawVal)) return;
    timer = setTimeout(() => (copy.val = value), ms);
  });
  scope.add(() => clearTimeout(timer));
  return copy;
}
