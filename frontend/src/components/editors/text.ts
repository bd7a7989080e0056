/** Text editor: visible strings and octet strings, written as typed (the server checks the length). */

import type { OdVariable } from "../../lib/od";
import { editText } from "../../lib/values";
import { EditorModel, editorOf, textField, type EditorOptions, type ValueEditor } from "./editor";

export function textEditor(variable: OdVariable, options: EditorOptions): ValueEditor {
  const model = new EditorModel(variable, options, (raw) => editText(variable, raw));
  return editorOf(model, textField(model, options));
}
