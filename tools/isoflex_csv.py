"""Reading the CSV files an isoflex run writes (history.csv, probes.csv, resultants.csv).

Shared by the plot_*.py scripts: one clear error line and exit status 2 for a missing file, an
empty file or missing columns; rows cut short by an interrupted run are skipped with a warning.
"""
import csv
import os
import sys


def fail(message):
    """Print `<script>: error: message` to stderr and exit with status 2."""
    print(f"{os.path.basename(sys.argv[0])}: error: {message}", file=sys.stderr)
    sys.exit(2)


def rows(path, required):
    """Yield (line number, {column: text}) for every complete data row of the CSV file `path`,
    after checking that it exists and has the `required` columns."""
    if not os.path.isfile(path):
        fail(f"no such file: {path}")
    with open(path, newline="") as f:
        reader = csv.reader(f)
        try:
            header = [name.strip() for name in next(reader)]
        except StopIteration:
            fail(f"{path} is empty")
        missing = [name for name in required if name not in header]
        if missing:
            fail(f"{path} lacks column(s): {', '.join(missing)}")
        for line_no, row in enumerate(reader, start=2):
            if not row:
                continue
            if len(row) < len(header):  # a row cut short by an interrupted run
                print(f"{os.path.basename(sys.argv[0])}: warning: {path}:{line_no}: incomplete row "
                      "ignored", file=sys.stderr)
                continue
            yield line_no, {name: value.strip() for name, value in zip(header, row)}


def numbers(path, line_no, row, names):
    """The named columns of a row as floats (exit status 2 if one is not a number)."""
    try:
        return {name: float(row[name]) for name in names}
    except ValueError:
        fail(f"{path}:{line_no}: not a number in {list(row.values())!r}")
