"""What `npm ci --prefix viewer` installs, for a machine without npm: every package
viewer/package-lock.json pins (three.js), its tarball fetched from the npm registry
and checked against the lock file's integrity hash before it is unpacked into
viewer/node_modules. Debian's npm brings over 300 packages with it; the build
needs the one file tree.

    python3 tools/fetch_viewer_deps.py [VIEWER_DIR]

NPM_CONFIG_REGISTRY names another registry, as it does for npm.
"""

import base64
import hashlib
import io
import json
import os
import shutil
import sys
import tarfile
import urllib.request
from pathlib import Path, PurePosixPath


def unpack(data, target):
    """The tarball's package/ tree into target: regular files and directories only,
    none outside it."""
    with tarfile.open(fileobj=io.BytesIO(data), mode="r:gz") as tar:
        for member in tar.getmembers():
            parts = PurePosixPath(member.name).parts[1:]  # below package/
            if not parts or ".." in parts or PurePosixPath(member.name).is_absolute():
                continue
            path = target.joinpath(*parts)
            if member.isdir():
                path.mkdir(parents=True, exist_ok=True)
            elif member.isfile():
                path.parent.mkdir(parents=True, exist_ok=True)
                path.write_bytes(tar.extractfile(member).read())


def main():
    viewer = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parent.parent / "viewer"
    lock = json.loads((viewer / "package-lock.json").read_text())
    registry = os.environ.get("NPM_CONFIG_REGISTRY", "https://registry.npmjs.org").rstrip("/")
    modules = viewer / "node_modules"
    # As npm ci: exactly what the lock file holds, nothing left from before.
    shutil.rmtree(modules, ignore_errors=True)
    for key, entry in lock["packages"].items():
        if not key:
            continue
        name = key.removeprefix("node_modules/")
        if "node_modules/" in name:
            sys.exit(f"fetch_viewer_deps.py: {key}: nested packages need npm (npm ci --prefix {viewer})")
        url = entry.get("resolved") or f"{registry}/{name}/-/{name.split('/')[-1]}-{entry['version']}.tgz"
        with urllib.request.urlopen(url, timeout=120) as response:
            data = response.read()
        algorithm, digest = entry["integrity"].split("-", 1)
        if hashlib.new(algorithm, data).digest() != base64.b64decode(digest):
            sys.exit(f"fetch_viewer_deps.py: {url} does not have the {algorithm} hash the lock file pins")
        unpack(data, modules / name)
        print(f"fetch_viewer_deps.py: {name} {entry['version']} from {url}")


if __name__ == "__main__":
    main()
