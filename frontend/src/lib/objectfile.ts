/**
 * The drive's object files (DRIVEPAR.TXT, USER_PAR.TXT) spelt from a project's values, so the browser restores
 * them as files through the server's one restore path (validated, written, read back, stored — as
 * `servostudio restore` does). Syntax of docs/file-formats.md: `0xIIII,sub=value` per line, integers in decimal,
 * REAL32/REAL64 as their IEEE-754 bit pattern, text as text; a text the syntax cannot carry is left out and named.
 */

import type { Scalar } from "./od";

export interface FileValue {
  index: number;
  subindex: number;
  data_type: string;
  value: Scalar;
  /** The file the value belongs to (null: the project does not set it). */
  file: string | null;
}

export interface ObjectFiles {
  /** File name → its text, in the order the files were first met. */
  files: Map<string, string>;
  /** Values that no object file can carry, with the reason. */
  left: string[];
}

const address = (index: number, subindex: number) => `0x${index.toString(16).toUpperCase().padStart(4, "0")},${subindex}`;

/** The bit pattern of a REAL value as the object file writes it (little-endian IEEE-754, read as an unsigned). */
export function realBits(value: number, dataType: string): string {
  const view = new DataView(new ArrayBuffer(8));
  if (dataType.toUpperCase() === "REAL64") {
    view.setFloat64(0, value, true);
    return view.getBigUint64(0, true).toString();
  }
  view.setFloat32(0, value, true);
  return String(view.getUint32(0, true));
}

/** Why a text cannot be an object-file value: empty, padded, starting like a number, or with ';' or a line break. */
export function unwritableText(text: string): string | null {
  if (text === "" || text.trim() !== text) return "empty or padded text";
  if (/^[+\-0-9]/.test(text)) return "text that starts like a number";
  return /[;\r\n]/.test(text) ? "text with ';' or a line break" : null;
}

function spelt(row: FileValue): string | { left: string } {
  const { value, data_type: dataType } = row;
  if (value === null) return { left: "no value" };
  if (typeof value === "number") return /^REAL(32|64)$/i.test(dataType) ? realBits(value, dataType) : String(Math.trunc(value));
  return unwritableText(value) === null ? value : { left: unwritableText(value) ?? "" };
}

/** The object files of the values the project sets (rows without a file are left alone). */
export function objectFiles(rows: FileValue[]): ObjectFiles {
  const lines = new Map<string, string[]>();
  const left: string[] = [];
  for (const row of rows) {
    if (row.file === null) continue;
    const text = spelt(row);
    if (typeof text !== "string") {
      left.push(`${address(row.index, row.subindex)}: ${text.left}`);
      continue;
    }
    const file = lines.get(row.file) ?? [];
    file.push(`${address(row.index, row.subindex)}=${text}`);
    lines.set(row.file, file);
  }
  return { files: new Map([...lines].map(([name, entries]) => [name, entries.join("\n") + "\n"])), left };
}
