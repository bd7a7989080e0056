/**
 * Bit-field editor: a word typed raw (hex), and its fields one per line with the current value; single bits get a
 * checkbox that follows the typed word and sets its bit in it (tick, then Write).
 */

import { h, untrack, valueOf, type Bindable } from "../../lib/dom";
import { decodeBits, extractBits, fieldLabel, insertBits, type BitField } from "../../lib/bits";
import { formatHex } from "../../lib/numbers";
import { hexWidth, type OdVariable, type Scalar } from "../../lib/od";
import { editText, parseValue } from "../../lib/values";
import { EditorModel, editorOf, textField, type EditorOptions, type ValueEditor } from "./editor";

export function bitsEditor(variable: OdVariable, options: EditorOptions): ValueEditor {
  const model = new EditorModel(variable, options, (raw) => editText(variable, raw));
  return editorOf(model, textField(model, options));
}

/**
 * The fields of `variable` in `current`; with an editor, a checkbox per single bit toggles that bit in the editor's
 * text (the word being typed, or the current value while its text does not parse).
 */
export function bitFields(variable: OdVariable, current: Bindable<Scalar>, editor: ValueEditor | null): HTMLElement {
  const word = () => {
    const raw = valueOf(current);
    return typeof raw === "number" ? raw : 0;
  };
  const typedWord = () => {
    if (!editor) return word();
    const parsed = parseValue(variable, editor.text.val);
    return parsed.ok && typeof parsed.raw === "number" ? parsed.raw : word();
  };
  const control = (field: BitField) => {
    const value = () => extractBits(word(), field.first, field.last);
    if (!editor || field.first !== field.last) return h("span", { class: () => (value() ? "on" : "") }, () => String(value()));
    const box: HTMLInputElement = h("input", {
      type: "checkbox", title: `Toggle bit ${field.first}`,
      checked: () => extractBits(typedWord(), field.first, field.first) === 1,
      onchange: () => {
        const base = untrack(typedWord);
        editor.setText(formatHex(insertBits(base, field.first, field.last, box.checked ? 1 : 0), hexWidth(variable.data_type)));
      },
    });
    return box;
  };
  const cells = decodeBits(0, variable.bits).map((field) => [
    h("span", { class: "mono muted" }, fieldLabel(field)),
    h("span", { class: () => (extractBits(word(), field.first, field.last) ? "on" : "") }, field.name),
    control(field),
  ]);
  return h("section", null,
    h("div", { class: "muted", style: { marginBottom: "4px" } }, editor ? "Bits (tick, then Write)" : "Bits"),
    h("div", { class: "bits" }, cells));
}
