/**
 * Value editors, one per kind of value, used by the parameter editor and the dashboard: `valueEditor` picks the
 * one an entry needs (the same rule everywhere).
 */

import { enumOptions, valueKind, type OdVariable } from "../../lib/od";
import { bitsEditor } from "./bits";
import type { EditorOptions, ValueEditor } from "./editor";
import { enumEditor, type EnumEditorOptions } from "./enum";
import { numberEditor } from "./number";
import { pointerEditor } from "./pointer";
import { textEditor } from "./text";

export type EditorKind = "enum" | "pointer" | "bits" | "text" | "number";

/** Enumerated integers get a list; pointers and words with bit fields are typed raw; texts as text; else numbers. */
export function editorKind(variable: OdVariable): EditorKind {
  const kind = valueKind(variable.data_type);
  if (kind === "integer" && enumOptions(variable).length > 0) return "enum";
  if (kind === "string" || kind === "bytes") return "text";
  if (variable.is_pointer) return "pointer";
  if (variable.bits.length > 0) return "bits";
  return "number";
}

const EDITORS: Record<EditorKind, (variable: OdVariable, options: EnumEditorOptions) => ValueEditor> = {
  enum: enumEditor,
  pointer: pointerEditor,
  bits: bitsEditor,
  text: textEditor,
  number: numberEditor,
};

export function valueEditor(variable: OdVariable, options: EditorOptions | EnumEditorOptions): ValueEditor {
  return EDITORS[editorKind(variable)](variable, options);
}

export type { EditorOptions, ValueEditor } from "./editor";
export { bitFields, bitsEditor } from "./bits";
export { enumEditor, enumList } from "./enum";
export { numberEditor } from "./number";
export { pointerEditor, pointerTarget } from "./pointer";
export { textEditor } from "./text";
