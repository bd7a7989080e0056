/**
 * The sequence editor's state: the project's SEQUENCE.TXT of the axis is the source of truth; the editor holds its
 * sequences (the server's JSON form), sends the text they make to the server's file reader after every change (the
 * one validation, with the chaining graph), saves it back to the project, imports and exports files, and reads and
 * writes the drive's memory.
 */

import { sequencesApi, type KeywordCatalog, type SequenceCheck, type SequenceRow } from "../../client/sequences";
import { state, type State } from "../../lib/dom";
import type { IoNames } from "../../lib/io-names";
import { failure, type Message } from "../ui";
import { merged, newSequence, toText, type Located, type Value } from "./text";

export interface AxisRef {
  bus: string;
  node: number;
  project: string;
  axis: string;
}

export class SequenceModel {
  readonly rows: State<SequenceRow[]> = state([]);
  readonly selected = state(1);
  readonly check: State<SequenceCheck | null> = state(null);
  readonly lines: State<Map<number, Located>> = state(new Map());
  readonly saved = state("");
  readonly message: State<Message | null> = state(null);
  readonly busy = state(false);
  /** The drive's I/O configuration's names for the pattern bits (docs/io.md); null offline or until read. */
  readonly ioNames: State<IoNames | null> = state(null);
  private revision: string | null = null;
  private pending: ReturnType<typeof setTimeout> | null = null;

  constructor(readonly ref: AxisRef, readonly catalog: KeywordCatalog) {}

  get text(): string {
    return toText(this.rows.rawVal).text;
  }

  /** The project's SEQUENCE.TXT, read into the editor. */
  async load(): Promise<void> {
    const file = await sequencesApi.project(this.ref.project, this.ref.axis);
    this.revision = file.revision;
    const checked = await sequencesApi.check(file.text);
    if (!checked.ok) {
      this.check.val = checked;
      this.message.val = { text: "The project's SEQUENCE.TXT has errors: fix the file (see the issues below).", tone: "error" };
      return;
    }
    this.rows.val = checked.sequences ?? [];
    this.saved.val = this.text;
    await this.recheck();
  }

  /** Any change: the rows replaced, the file checked again shortly after. */
  setRows(rows: SequenceRow[]): void {
    this.rows.val = rows;
    if (this.pending) clearTimeout(this.pending);
    this.pending = setTimeout(() => void this.recheck(), 200);
  }

  async recheck(): Promise<void> {
    const { text, lines } = toText(this.rows.rawVal);
    const checked = await sequencesApi.check(text);
    if (text !== this.text) return; // edited again meanwhile: that check follows
    this.lines.val = lines;
    this.check.val = checked;
  }

  setValue(number: number, keyword: string, value: Value): void {
    this.setRows(this.rows.rawVal.map((row) => (row.sequence === number ? { ...row, values: { ...row.values, [keyword]: value } } : row)));
  }

  /** The slot's type: "" empties it; another type starts from that type's defaults (common values kept). */
  setType(number: number, type: string): void {
    const others = this.rows.rawVal.filter((row) => row.sequence !== number);
    const previous = this.rows.rawVal.find((row) => row.sequence === number);
    const rows = type ? [...others, newSequence(this.catalog, type, number, previous)] : others;
    this.setRows(rows.sort((a, b) => a.sequence - b.sequence));
  }

  /** Import a SEQUENCE.TXT: checked first; a file with an error changes nothing. */
  async import(text: string, mode: "load" | "merge"): Promise<boolean> {
    const checked = await sequencesApi.check(text);
    if (!checked.ok) {
      this.check.val = checked;
      this.lines.val = new Map();
      this.message.val = { text: `Not imported: ${checked.issues.length} error(s) in the file`, tone: "error", testid: "sequence-import-refused" };
      return false;
    }
    const file = checked.sequences ?? [];
    this.setRows(merged(this.rows.rawVal, file, mode));
    this.message.val = { text: `Imported ${file.length} sequence(s) (${mode.toUpperCase()})`, tone: "ok" };
    return true;
  }

  /** Save the editor's text as the project's SEQUENCE.TXT (refused by the server if it has an error). */
  async save(): Promise<void> {
    await this.guard("Saved to the project", async () => {
      const text = this.text;
      const written = await sequencesApi.saveProject(this.ref.project, this.ref.axis, text, this.revision);
      this.revision = written.revision;
      this.saved.val = text;
    });
  }

  /** Run one action with the busy flag, reporting its outcome. */
  async guard(done: string, work: () => Promise<void>): Promise<boolean> {
    this.busy.val = true;
    try {
      await work();
      this.message.val = { text: done, tone: "ok", testid: "sequence-message" };
      return true;
    } catch (error) {
      this.message.val = failure(error, "sequence-error");
      return false;
    } finally {
      this.busy.val = false;
    }
  }
}

export async function createModel(ref: AxisRef): Promise<SequenceModel> {
  return new SequenceModel(ref, await sequencesApi.keywords());
}

/** The issues of the last check that concern one sequence (by the line of the text it was checked as). */
export function issuesOf(model: SequenceModel, number: number): { keyword: string | null; reason: string }[] {
  const check = model.check.val;
  const lines = model.lines.val;
  return (check?.issues ?? []).filter((issue) => lines.get(issue.line)?.sequence === number);
}
