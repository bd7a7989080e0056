/**
 * Channel picker: an object chosen by name search over the dictionary (address, name or description words, the
 * parameter editor's search), among the objects the recorder can sample: readable, PDO-mappable numbers of 8, 16
 * or 32 bits. The value is the object's key as captures spell it, `0x606C,0` ("" = none).
 */

import { h, state, type State } from "../../lib/dom";
import { entries, isReadable, type Dictionary, type Entry } from "../../lib/od";
import { buildIndex, search, type Searchable } from "../../lib/search";

const RECORDABLE = /^(INTEGER|UNSIGNED)(8|16|32)$|^REAL32$/;
const SHOWN = 8;

export function objectKey(entry: Entry): string {
  return `0x${entry.object.index.toString(16).toUpperCase().padStart(4, "0")},${entry.variable.subindex}`;
}

/** The search index of the objects a recorder can sample. */
export function recordableIndex(dictionary: Dictionary): Searchable[] {
  return buildIndex(entries(dictionary).filter(({ variable }) =>
    variable.pdo_mappable && isReadable(variable.access) && RECORDABLE.test(variable.data_type.toUpperCase())));
}

/** The entry a key names ("0x606C,0"), if the index has it. */
export function entryOf(index: readonly Searchable[], key: string): Entry | undefined {
  return index.find((item) => objectKey(item.entry) === key)?.entry;
}

export function describeKey(index: readonly Searchable[], key: string): string {
  const entry = entryOf(index, key);
  return entry ? `${key} ${entry.variable.name}` : key;
}

export interface PickerProps {
  value: State<string>;
  index: Searchable[];
  placeholder: string;
  testid: string;
}

export function objectPicker(props: PickerProps): HTMLElement {
  const query = state<string | null>(null); // null: not searching, the input shows the chosen object
  const input: HTMLInputElement = h("input", {
    type: "search", placeholder: props.placeholder, "data-testid": props.testid, style: { width: "230px" },
    value: () => query.val ?? describeKey(props.index, props.value.val),
    oninput: () => (query.val = input.value),
    onfocus: () => (query.val = ""),
    onblur: () => setTimeout(() => (query.val = null), 150), // a click on a result lands first
    onkeydown: (event: KeyboardEvent) => {
      if (event.key === "Enter") pick(search(props.index, input.value)[0]);
    },
  });
  const pick = (entry: Entry | undefined) => {
    if (entry) props.value.val = objectKey(entry);
    query.val = null;
    input.blur();
  };
  const results = () => {
    const text = query.val;
    if (text === null || text.trim() === "") return null;
    return h("div", { class: "picker-results", "data-testid": `${props.testid}-results`, style: RESULTS_STYLE },
      search(props.index, text).slice(0, SHOWN).map((entry) => h("button", {
        class: "link", style: { display: "block", textAlign: "left", width: "100%" }, "data-testid": "picker-result",
        onmousedown: (event: MouseEvent) => event.preventDefault(), onclick: () => pick(entry),
      }, h("span", { class: "mono" }, objectKey(entry)), ` ${entry.variable.name}`, entry.variable.unit ? h("span", { class: "muted" }, ` [${entry.variable.unit}]`) : null)));
  };
  const clear = h("button", { title: "None", "aria-label": "Clear", "data-testid": `${props.testid}-clear`, onclick: () => (props.value.val = "") }, "×");
  return h("span", { style: { position: "relative", display: "inline-flex", gap: "2px" } }, input, clear, results);
}

const RESULTS_STYLE = {
  position: "absolute", top: "100%", left: "0", zIndex: "20", minWidth: "320px", maxHeight: "260px", overflowY: "auto",
  background: "var(--panel)", border: "1px solid var(--line)", borderRadius: "4px", padding: "4px",
};
