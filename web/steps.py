"""Seconds between two of the page's scripted steps, from Chromium's log (web/time.sh).

`python3 web/steps.py LOG FIRST SECOND`: LOG is Chromium's stderr with `--enable-logging`, whose
lines start `[pid:tid:MMDD/HHMMSS.micro:`; the page logs each step as it runs it (`step: View(Split)`).
Prints the seconds from the first step named FIRST to the first named SECOND after it; exits 1 if
either is missing.
"""

import re
import sys


def main() -> int:
    log, first, second = sys.argv[1:4]
    text = open(log, errors="replace").read()
    line = r":\d{4}/(\d\d)(\d\d)(\d\d\.\d+):INFO:CONSOLE[^\n]*step: "
    start = re.search(line + re.escape(first), text)
    end = start and re.search(line + re.escape(second), text[start.end():])
    if not (start and end):
        return 1
    seconds = lambda m: int(m[1]) * 3600 + int(m[2]) * 60 + float(m[3])
    # Across midnight the clock starts again.
    print(f"{(seconds(end) - seconds(start)) % 86400:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
