#!/usr/bin/env bash
# Serves the built page (web/build.sh) at http://localhost:8000/ (`bash web/serve.sh [PORT]`).
# Any static web server does; this one needs only Python 3.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ ! -f web/dist/index.html ]; then
    echo "web/dist/ is not built: run bash web/build.sh first" >&2
    exit 1
fi
command -v python3 >/dev/null || apt-get install -y python3
exec python3 web/serve.py --root web/dist --port "${1:-8000}"
