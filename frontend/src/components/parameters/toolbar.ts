/** The editor's toolbar: search (debounced), group, Only differences, the count, and a place for the bulk actions. */

import { h, type State } from "../../lib/dom";
import type { Dictionary, Entry } from "../../lib/od";
import { ALL_GROUPS, APPLICATION_GROUPS } from "./rows";

const TYPING_DEBOUNCE_MS = 60;

export interface ToolbarProps {
  dictionary: Dictionary;
  application: { title: string } | null;
  text: State<string>;
  group: State<string>;
  onlyDiff: State<boolean>;
  /** The entries shown (the count). */
  shown: State<Entry[]>;
  total: number;
  /** Offer Only differences (a drive and a project to compare). */
  compare: boolean;
  /** The user changed the search or the group (not a URL change): keep it in the URL. */
  onQuery(): void;
  /** Only differences was ticked or cleared. */
  onOnlyDiff(checked: boolean): void;
  /** ArrowDown or Enter in the search field: go to the table. */
  onEnterTable(): void;
  bulk: HTMLElement;
}

export function parameterToolbar(props: ToolbarProps): { element: HTMLElement; search: HTMLInputElement } {
  let typingTimer = 0;
  const search: HTMLInputElement = h("input", {
    type: "search", placeholder: "Search index, name or description ( / )", style: { width: "300px" },
    "data-testid": "param-search", "aria-label": "Search parameters", value: props.text,
    oninput: () => {
      clearTimeout(typingTimer);
      typingTimer = window.setTimeout(() => {
        props.text.val = search.value;
        props.onQuery();
      }, TYPING_DEBOUNCE_MS);
    },
    onkeydown: (event: KeyboardEvent) => {
      if (event.key === "ArrowDown" || event.key === "Enter") {
        event.preventDefault();
        props.onEnterTable();
      }
    },
  });
  const group: HTMLSelectElement = h("select", {
    "data-testid": "param-group", "aria-label": "Group", value: props.group,
    onchange: () => {
      props.group.val = group.value;
      props.onQuery();
    },
  },
  props.application ? h("option", { value: APPLICATION_GROUPS }, `${props.application.title}: its groups`) : null,
  h("option", { value: ALL_GROUPS }, props.application ? "All groups (Expert)" : "All groups"),
  props.dictionary.groups.map((name) => h("option", { value: name }, name)));
  const onlyDiff: HTMLInputElement = h("input", {
    type: "checkbox", "data-testid": "param-only-diff", checked: props.onlyDiff,
    onchange: () => props.onOnlyDiff(onlyDiff.checked),
  });
  const element = h("div", { class: "toolbar" },
    search, group,
    props.compare ? h("label", { class: "check", title: "Only entries whose drive value differs from the project" }, onlyDiff, "Only differences") : null,
    // Bound to the list itself, so every filtering rewrites the count (the UI bench waits for that).
    h("span", { class: "muted", "data-testid": "param-count" }, () => `${props.shown.val.length} of ${props.total} entries`),
    h("span", { class: "grow" }), props.bulk);
  return { element, search };
}
