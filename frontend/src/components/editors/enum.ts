/**
 * Enumeration editor: a `<select>` over the dictionary's enumeration (`text (value)`), with one more option for a
 * current value the enumeration does not name. Also the list of the enumeration with the current value marked.
 */

import { h, valueOf, type Bindable } from "../../lib/dom";
import { enumOptions, type OdVariable, type Scalar } from "../../lib/od";
import { EditorModel, editorOf, type EditorOptions, type ValueEditor } from "./editor";

export interface EnumEditorOptions extends EditorOptions {
  /** The option shown for a current value the enumeration does not name. */
  unknownLabel?: (value: string) => string;
}

export function enumEditor(variable: OdVariable, options: EnumEditorOptions): ValueEditor {
  const choices = enumOptions(variable);
  const show = (raw: Scalar) => (raw === null || raw === undefined ? String(choices[0]?.value ?? "") : String(raw));
  const model = new EditorModel(variable, options, show);
  const unknownLabel = options.unknownLabel ?? ((value: string) => `${value} (not in the list)`);
  const select: HTMLSelectElement = h("select", {
    ...options.attrs,
    onchange: () => model.setText(select.value),
    onkeydown: (event: KeyboardEvent) => model.onKey(event),
  }, () => {
    // The options are rebuilt with the text: the one shown is the selected one, an unnamed value gets its own.
    const current = model.text.val;
    const named = choices.some((choice) => String(choice.value) === current);
    return [
      named || current === "" ? null : h("option", { value: current, selected: true }, unknownLabel(current)),
      choices.map((choice) => h("option", { value: String(choice.value), selected: String(choice.value) === current },
        `${choice.text} (${choice.value})`)),
    ];
  });
  return editorOf(model, select);
}

/** The enumeration as a list, the entry's current value marked. */
export function enumList(variable: OdVariable, current: Bindable<Scalar>): HTMLElement {
  const marked = (value: number) => () => (valueOf(current) === value ? "current" : "");
  return h("section", null, h("div", { class: "muted", style: { marginBottom: "4px" } }, "Values"),
    h("div", { class: "enum-list" }, enumOptions(variable).map((option) => [
      h("span", { class: () => `mono ${marked(option.value)()}` }, String(option.value)),
      h("span", { class: marked(option.value) }, option.text),
    ])));
}
