/**
 * The server's pydantic models as TypeScript types: `schema.d.ts` is generated from `/openapi.json` by
 * openapi-typescript (`make api-types`) and checked by `make test`, so a model change the frontend does not follow
 * fails the build (the check, then `tsc` at every use of a field that changed).
 */

import type { components } from "./schema";

export type Schemas = components["schemas"];

/**
 * `T` with some fields given a narrower type than the schema says (a state the server documents only as `str`,
 * a job result the schema leaves open). Each narrowed field must exist in `T`: a field the server dropped fails tsc.
 */
export type Narrow<T, U extends { [K in keyof U]: K extends keyof T ? unknown : never }> = Omit<T, keyof U> & U;
