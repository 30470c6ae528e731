"""TLS files checked before a connection uses them (docs/scale_out.md, "Security"): each a
regular, readable file holding a PEM of the right kind, the key the certificate's. A wrong
file otherwise shows only after a connection attempt, as the scheduler refusing this client,
when the local file is the problem. Python's own ``ssl`` module reads them, as Dask will."""

from __future__ import annotations

import re
import ssl

from . import files

#: The largest TLS file read: a certificate chain or a key is a few kilobytes.
MAX_PEM_BYTES = 1 << 20


class _Encrypted(Exception):
    """Raised by the passphrase callback: the key asks for a passphrase."""


def _no_passphrase():
    raise _Encrypted


def _reason(e: Exception) -> str:
    """The ssl module's reason, without its source location."""
    text = str(e.args[-1]) if isinstance(e, ssl.SSLError) and e.args else str(e)
    return re.sub(r"\s*\(_ssl\.c:\d+\)$", "", text)


def pem_text(label: str, path) -> str:
    """The text of the TLS file ``path``, given as ``label`` (an option or a configuration
    key): a ValueError naming both unless it is a regular, readable, non-empty ASCII file of
    at most MAX_PEM_BYTES (a FIFO is never opened)."""
    try:
        files.regular_file(path, label)
        with open(path, "rb") as f:
            data = f.read(MAX_PEM_BYTES + 1)
    except FileNotFoundError:
        raise ValueError(f"{label} {path!r}: no such file") from None
    except OSError as e:
        raise ValueError(f"{label} {path!r}: cannot be read ({e.strerror or e})") from None
    if len(data) > MAX_PEM_BYTES:
        raise ValueError(f"{label} {path!r}: larger than {MAX_PEM_BYTES} bytes, not a PEM file")
    if not data.strip():
        raise ValueError(f"{label} {path!r}: the file is empty")
    try:
        return data.decode("ascii")
    except UnicodeDecodeError:
        raise ValueError(f"{label} {path!r}: not a PEM file (it is not text; a DER file can "
                         "be converted with openssl)") from None


def check_certificate(label: str, path) -> None:
    """``path`` holds a PEM certificate the ssl module loads (a CA's, or this client's); else
    a ValueError naming ``label`` and the file."""
    text = pem_text(label, path)
    try:
        ssl.SSLContext(ssl.PROTOCOL_TLS_CLIENT).load_verify_locations(cadata=text)
    except (ssl.SSLError, ValueError) as e:
        hint = "; it holds a private key" if "PRIVATE KEY-----" in text else ""
        raise ValueError(f"{label} {path!r}: holds no PEM certificate (-----BEGIN "
                         f"CERTIFICATE-----) that Python's ssl module can load "
                         f"({_reason(e)}){hint}") from None


def check_key(label: str, path, cert_label: str, cert) -> None:
    """``path`` holds the unencrypted PEM private key of the certificate ``cert`` (checked
    first by check_certificate); else a ValueError naming ``label`` and the file."""
    text = pem_text(label, path)
    if "PRIVATE KEY-----" not in text:
        raise ValueError(f"{label} {path!r}: holds no PEM private key (-----BEGIN PRIVATE "
                         "KEY-----)")
    try:
        ssl.SSLContext(ssl.PROTOCOL_TLS_CLIENT).load_cert_chain(cert, path,
                                                                password=_no_passphrase)
    except _Encrypted:
        # without a callback OpenSSL would ask for the passphrase on the terminal
        raise ValueError(f"{label} {path!r}: the key is encrypted with a passphrase, which "
                         "Dask cannot give: use a key without one, readable by you only"
                         ) from None
    except (ssl.SSLError, ValueError) as e:
        raise ValueError(f"{label} {path!r}: not the private key of {cert_label} {cert!r} "
                         f"({_reason(e)})") from None
