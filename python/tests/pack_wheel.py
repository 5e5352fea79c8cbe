"""Packs the extension module that `cargo test` built into a wheel, as maturin lays it out.

    python pack_wheel.py --library target/debug/lib_camchain.so --out DIR

The wheel holds the Python package (`camchain/*.py`), the extension module under the name
this interpreter imports (`camchain/_camchain<EXT_SUFFIX>`) and the metadata a wheel needs
(`METADATA`, `WHEEL`, `RECORD` with every file's SHA-256), tagged for this interpreter and
platform. tests/wheel.rs uses it so that the Python suite runs against the module the
workspace's test build has already compiled, instead of compiling the workspace again
through maturin (`CAMCHAIN_WHEEL=maturin` builds the test wheel with maturin instead).
Prints the wheel's path.
"""

import argparse
import base64
import hashlib
import pathlib
import re
import sys
import sysconfig
import zipfile

HERE = pathlib.Path(__file__).resolve().parent
PACKAGE = HERE.parent


def version():
    text = (PACKAGE.parent / "Cargo.toml").read_text()
    section = text[text.index("[workspace.package]"):]
    return re.search(r'^version = "([^"]+)"', section, flags=re.M).group(1)


def record_line(name, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{name},sha256={digest},{len(data)}"


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--library", required=True, type=pathlib.Path)
    parser.add_argument("--out", required=True, type=pathlib.Path)
    args = parser.parse_args()
    v = version()
    python = f"cp{sys.version_info.major}{sys.version_info.minor}"
    platform = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    tag = f"{python}-{python}-{platform}"
    dist = f"camchain-{v}.dist-info"
    files = {}
    for source in sorted((PACKAGE / "camchain").glob("*.py")):
        files[f"camchain/{source.name}"] = source.read_bytes()
    files[f"camchain/_camchain{sysconfig.get_config_var('EXT_SUFFIX')}"] = args.library.read_bytes()
    files[f"{dist}/METADATA"] = (
        f"Metadata-Version: 2.1\nName: camchain\nVersion: {v}\n"
        "Requires-Python: >=3.9\nRequires-Dist: numpy>=1.21\n"
    ).encode()
    files[f"{dist}/WHEEL"] = (
        f"Wheel-Version: 1.0\nGenerator: camchain pack_wheel.py\nRoot-Is-Purelib: false\nTag: {tag}\n"
    ).encode()
    record = [record_line(name, data) for name, data in files.items()]
    record.append(f"{dist}/RECORD,,")
    files[f"{dist}/RECORD"] = ("\n".join(record) + "\n").encode()
    args.out.mkdir(parents=True, exist_ok=True)
    wheel = args.out / f"camchain-{v}-{tag}.whl"
    with zipfile.ZipFile(wheel, "x", compression=zipfile.ZIP_DEFLATED) as z:
        for name, data in files.items():
            info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
            info.external_attr = (0o755 if name.endswith(".so") else 0o644) << 16
            z.writestr(info, data, compress_type=zipfile.ZIP_DEFLATED)
    print(wheel)


if __name__ == "__main__":
    main()
