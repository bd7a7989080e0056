/**
 * Pointer editor (dataflow pointers: `index << 16 | sub << 8 | bit-or-size`): the word typed raw (hex), its target
 * shown symbolically, and a picker over the PDO-mappable entries plus the bit/size that writes the word.
 */

import { h, valueOf, type Bindable } from "../../lib/dom";
import { formatHex } from "../../lib/numbers";
import { address, entryKey, type Entry, type OdVariable, type Scalar } from "../../lib/od";
import { decodePointer, encodePointer, formatPointer, type PointerTarget } from "../../lib/pointer";
import { editText } from "../../lib/values";
import { EditorModel, editorOf, textField, type EditorOptions, type ValueEditor } from "./editor";

export function pointerEditor(variable: OdVariable, options: EditorOptions): ValueEditor {
  const model = new EditorModel(variable, options, (raw) => editText(variable, raw));
  return editorOf(model, textField(model, options));
}

function targetOf(raw: Scalar): PointerTarget | null {
  return typeof raw === "number" && raw > 0 ? decodePointer(raw) : null;
}

/**
 * Where `current` points, and the picker: choosing an entry (or a bit/size) puts the encoded pointer into the
 * editor's text. Without an editor (read-only, offline) the picker is disabled.
 */
export function pointerTarget(current: Bindable<Scalar>, entries: Entry[], editor: ValueEditor | null): HTMLElement {
  const byKey = new Map(entries.map((entry) => [entry.key, entry]));
  const mappable = entries.filter((entry) => entry.variable.pdo_mappable);
  const target = () => targetOf(valueOf(current));
  const targetEntry = () => {
    const found = target();
    return found ? byKey.get(entryKey(found.index, found.subindex)) : undefined;
  };
  const apply = () => {
    const chosen = byKey.get(picker.value);
    const bitValue = Number(bit.value);
    if (!editor || !chosen || !Number.isInteger(bitValue) || bitValue < 0 || bitValue > 255) return;
    editor.setText(formatHex(encodePointer({ index: chosen.object.index, subindex: chosen.variable.subindex, bit: bitValue }), 8));
  };
  const picker: HTMLSelectElement = h("select", {
    "data-testid": "pointer-picker", "aria-label": "Pointer target", disabled: !editor, onchange: apply,
    value: () => (targetEntry()?.variable.pdo_mappable ? targetEntry()!.key : ""),
  }, h("option", { value: "" }, "Link to…"),
  mappable.map((entry) => h("option", { value: entry.key }, `${address(entry)} ${entry.variable.name}`)));
  const bit: HTMLInputElement = h("input", {
    type: "text", style: { width: "52px" }, "aria-label": "Bit or size", disabled: !editor, oninput: apply,
    value: () => String(target()?.bit ?? 0),
  });
  return h("section", null,
    h("div", null, h("span", { class: "muted" }, "Points to "), () => {
      const raw = valueOf(current);
      return typeof raw === "number" ? formatPointer(raw) : "—";
    }, () => (targetEntry() ? h("span", null, ` · ${targetEntry()!.variable.name}`) : null)),
    h("div", { class: "editor", style: { marginTop: "6px" } }, picker, h("span", { class: "muted" }, "bit/size"), bit));
}
