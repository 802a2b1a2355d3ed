#!/usr/bin/python3
"""Validate JSON files against the project's schemas (Debian's python3-jsonschema).

usage: validate_json.py SCHEMA_DIR SCHEMA_NAME FILE... [--expect-invalid]
Exit 0 when every file validates (or, with --expect-invalid, when every file is rejected).
"""
import json
import os
import sys

import jsonschema


def main():
    args = [a for a in sys.argv[1:] if a != "--expect-invalid"]
    expect_invalid = "--expect-invalid" in sys.argv
    schema_dir, name, files = args[0], args[1], args[2:]
    store = {}
    for entry in os.listdir(schema_dir):
        if entry.endswith(".schema.json"):
            with open(os.path.join(schema_dir, entry)) as f:
                s = json.load(f)
            store[s["$id"]] = s
    with open(os.path.join(schema_dir, name)) as f:
        schema = json.load(f)
    jsonschema.Draft7Validator.check_schema(schema)
    resolver = jsonschema.RefResolver.from_schema(schema, store=store)
    validator = jsonschema.Draft7Validator(schema, resolver=resolver)
    failed = 0
    for path in files:
        with open(path) as f:
            doc = json.load(f)
        errors = sorted(validator.iter_errors(doc), key=lambda e: list(e.path))
        if expect_invalid:
            if not errors:
                print(f"{path}: accepted by {name}, expected a rejection")
                failed += 1
        elif errors:
            print(f"{path}: {errors[0].message} at {list(errors[0].path)}")
            failed += 1
    print(f"{len(files) - failed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
