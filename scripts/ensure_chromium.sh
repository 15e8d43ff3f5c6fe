#!/usr/bin/env sh
# `make test` needs a real Chromium: the viewer test renders the exported page in it.
# Found: nothing to do. Missing: install Debian's chromium when this user may (root, or
# sudo without a password prompt); otherwise stop with one line giving the command to run.
set -eu
for name in chromium chromium-browser google-chrome; do
    if command -v "$name" >/dev/null 2>&1; then exit 0; fi
done
if [ "$(id -u)" -eq 0 ]; then
    sudo=""
elif command -v sudo >/dev/null 2>&1 && sudo -n true >/dev/null 2>&1; then
    sudo="sudo "
else
    echo "make test: the viewer test needs Chromium, which is not installed; run: sudo apt-get install -y chromium" >&2
    exit 1
fi
if ! command -v apt-get >/dev/null 2>&1; then
    echo "make test: the viewer test needs Chromium, which is not installed; install your system's chromium package" >&2
    exit 1
fi
echo "make test: installing Debian's chromium for the viewer test (${sudo}apt-get install chromium)"
export DEBIAN_FRONTEND=noninteractive
${sudo}apt-get update -qq
${sudo}apt-get install -y -qq chromium >/dev/null
