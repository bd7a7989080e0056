/**
 * The names the I/O configuration gives (docs/io.md), for the pages that show bits of the drive's I/O: the dashboard
 * labels the inputs of 0x60FD and the outputs of 0x60FE,1 with the input's name and its function; the sequence
 * editor's bit patterns name each bit of the conditional input 0x3601,3 by the input routed to it, and each sequence
 * output 0x3602,1 bit by the output that shows it.
 */

export interface NamedFunction {
  key: string;
  label: string;
  condition_bit?: number | null;
}

export interface NamedLine {
  name: string;
  function: string;
  /** its bit in 0x60FD / 0x60FE,1 */
  bit: number;
}

export interface IoNamesSource {
  functions: NamedFunction[];
  output_functions: NamedFunction[];
  inputs: NamedLine[];
  outputs: NamedLine[];
  routing: string;
}

export interface IoNames {
  /** bit of 0x60FD / 0x60FE,1 → "IN3: Positive limit switch" */
  inputs: Map<number, string>;
  outputs: Map<number, string>;
  /** bit of the conditional input 0x3601,3 → the input that feeds it */
  conditions: Map<number, string>;
  /** bit of the sequence outputs 0x3602,1 → the output that shows it */
  sequenceOutputs: Map<number, string>;
}

const NO_FUNCTION = new Set(["none", "general", "other"]);

/** The label of a line: its name, and its function unless it has none. */
export function lineLabel(line: NamedLine, functions: NamedFunction[]): string {
  if (NO_FUNCTION.has(line.function)) return line.name;
  const found = functions.find((candidate) => candidate.key === line.function);
  return `${line.name}: ${found?.label ?? line.function}`;
}

export function ioNames(source: IoNamesSource): IoNames {
  const names: IoNames = { inputs: new Map(), outputs: new Map(), conditions: new Map(), sequenceOutputs: new Map() };
  source.inputs.forEach((line) => {
    names.inputs.set(line.bit, lineLabel(line, source.functions));
    const bit = source.functions.find((candidate) => candidate.key === line.function)?.condition_bit;
    if (bit !== null && bit !== undefined) names.conditions.set(bit, line.name);
  });
  source.outputs.forEach((line) => {
    names.outputs.set(line.bit, lineLabel(line, source.output_functions));
    const match = /^sequence_output_(\d+)$/.exec(line.function);
    if (match) names.sequenceOutputs.set(Number(match[1]), line.name);
  });
  return names;
}
