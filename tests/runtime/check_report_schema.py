#!/usr/bin/env python3
"""check_report_schema.py SCHEMA REPORT...: validates vrflow run reports against the JSON Schema
(runtime/schema/vrflow-report.schema.json) with python3-jsonschema; prints each violation as
REPORT: PATH: MESSAGE and exits 1 when there is any, 0 when every report is valid."""
import json
import sys

import jsonschema

schema = json.load(open(sys.argv[1], encoding="utf-8"))
jsonschema.Draft202012Validator.check_schema(schema)
validator = jsonschema.Draft202012Validator(schema)
failed = False
for path in sys.argv[2:]:
    report = json.load(open(path, encoding="utf-8"))
    for error in sorted(validator.iter_errors(report), key=lambda e: list(map(str, e.path))):
        print(f"{path}: /{'/'.join(map(str, error.path))}: {error.message}")
        failed = True
sys.exit(1 if failed else 0)
