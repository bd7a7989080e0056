/**
 * Number editor: the value typed in the entry's unit (physical = raw × scale + offset), `.` as decimal separator
 * whatever the browser's language, `0x…` and `0b…` accepted; checked against the range before it is emitted raw.
 */

import type { OdVariable } from "../../lib/od";
import { editText } from "../../lib/values";
import { EditorModel, editorOf, textField, type EditorOptions, type ValueEditor } from "./editor";

export function numberEditor(variable: OdVariable, options: EditorOptions): ValueEditor {
  const model = new EditorModel(variable, options, (raw) => editText(variable, raw));
  return editorOf(model, textField(model, options, { inputmode: "decimal" }));
}
