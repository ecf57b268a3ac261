#!/usr/bin/python3
"""Prints one value of a JSON file for the table scripts: json_field.py FILE a.b.c [% | x | raw]
(% : the value x 100 with one decimal; x : three decimals; raw, the default: as it is)."""
import json
import sys

value = json.load(open(sys.argv[1]))
for key in sys.argv[2].split("."):
    value = value[key]
form = sys.argv[3] if len(sys.argv) > 3 else "raw"
print(f"{100 * value:.1f}" if form == "%" else f"{value:.3f}" if form == "x" else value)
