#!/usr/bin/python3
"""The README's job examples run as written (issue 14: it showed a one-line raster set that the
parser refused). Every fenced code block whose first line starts with `job =` is written to a
file and run with the real `levelsetd run`; each must succeed and write its band and mesh.

Usage: readme_examples.py LEVELSETD README.md SCRATCH_DIR
"""
import os
import re
import shutil
import subprocess
import sys


def job_blocks(readme_text):
    blocks = re.findall(r"^```[a-z]*\n(.*?)^```", readme_text, flags=re.S | re.M)
    return [b for b in blocks if b.lstrip().startswith("job =")]


def main():
    levelsetd, readme, scratch = sys.argv[1:4]
    shutil.rmtree(scratch, ignore_errors=True)
    os.makedirs(scratch)
    with open(readme, encoding="utf-8") as f:
        blocks = job_blocks(f.read())
    if not blocks:
        print("readme_examples: no job blocks found in", readme, file=sys.stderr)
        return 1
    failures = 0
    for i, block in enumerate(blocks):
        job = os.path.join(scratch, f"readme_{i}.conf")
        with open(job, "w", encoding="utf-8") as f:
            f.write(block)
        out = os.path.join(scratch, f"out_{i}")
        r = subprocess.run([levelsetd, "run", job, "-o", out, "-q"], capture_output=True, text=True, timeout=600)
        expected = [os.path.join(out, f"readme_{i}.{ext}") for ext in ("lsg", "stats.json")]
        missing = [p for p in expected if not os.path.isfile(p)]
        if r.returncode != 0 or missing:
            failures += 1
            print(f"readme_examples: block {i} failed (exit {r.returncode}, missing {missing}):\n{block}\n{r.stderr}",
                  file=sys.stderr)
    print(f"readme_examples: {len(blocks) - failures} of {len(blocks)} job blocks ran as written")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
