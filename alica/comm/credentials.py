"""A team's credentials: X.509 certificates for zenoh's TLS with mutual authentication, and its access control.

``alica team keys --out DIR NAME...`` (:func:`make_keys`) makes a folder of:

* ``ca.pem``, ``ca.key``: the team's certificate authority (an EC P-256 key).
  Its certificate goes to every host; its key stays with whoever adds members.
* ``NAME.pem``, ``NAME.key`` for every agent and for the control center
  (:data:`CENTER`): a certificate whose common name is the name, signed by the
  CA, good for TLS servers and clients; the key is readable by its owner only.
* ``roster.json``: ``{"members": [...], "center": "center"}``, the team.

A process of the team loads its own (:meth:`TeamKeys.load`, which checks
everything it can before a session opens) and opens its zenoh session with
:meth:`TeamKeys.zenoh_settings`: TLS links only, each side showing a
certificate of the team's CA (so nobody else connects, reads or writes), and
zenoh's access control at every session's ingress, so that a member speaks
only for itself:

* from member ``N``: ``put`` on ``P/m/N/**``, ``P/hb/N`` and
  ``P/center/events/N``; its liveliness token ``P/alive/N/*``; queryables and
  replies on ``P/hist/N`` and ``P/center/history/N``;
* from every member and the center: subscriptions, liveliness subscriptions,
  queries and liveliness queries on ``P/**``, and the operator's commands on
  ``P/center/operator`` (the center reaches the team through one agent, which
  forwards its commands; so the agents check the center's signature,
  :meth:`TeamKeys.verifies`, not the link they came over);
* the center's own session is a viewer fed through one agent: it takes from
  any member events (``P/center/events/*``), history answers
  (``P/center/history/*``, ``P/hist/*``), liveliness tokens (``P/alive/**``)
  and declarations, and nothing else.

Everything else arriving is dropped by zenoh; everything leaving is allowed.
The cryptography is the ``cryptography`` package's (X.509, ECDSA P-256 with
SHA-256) and zenoh's (TLS); this module only makes and checks the files.
"""

from __future__ import annotations

import datetime
import json
import os
import re
import secrets
import threading
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

from cryptography import x509
from cryptography.exceptions import InvalidSignature
from cryptography.hazmat.primitives import hashes, serialization
from cryptography.hazmat.primitives.asymmetric import ec
from cryptography.x509.oid import ExtendedKeyUsageOID, NameOID

from alica.errors import AlicaError

CENTER = "center"
"""The control center's identity name in a team's credentials."""
MAX_NAME = 64
"""The longest name a certificate holds (X.509's bound on a common name)."""
MAX_SIGNATURE = 256
"""The longest signature :meth:`TeamKeys.verifies` looks at, in bytes (an ECDSA P-256 one has at most 72)."""
CA = "ca"
ROSTER = "roster.json"
SKEW = datetime.timedelta(seconds=300)
"""How far back a new certificate is valid from: hosts' clocks may be this far apart (NTP)."""

_NAME = re.compile(r"[^/*$?#\s]+")
_DNS_LABEL = re.compile(r"[A-Za-z0-9](?:[A-Za-z0-9-]{0,61}[A-Za-z0-9])?")
ZENOH_MESSAGES = (
    "put",
    "delete",
    "declare_subscriber",
    "query",
    "declare_queryable",
    "reply",
    "liveliness_token",
    "declare_liveliness_subscriber",
    "liveliness_query",
)
"""Every message kind zenoh's access control (eclipse-zenoh 1.10) knows."""
_DECLARATIONS = ("declare_subscriber", "declare_liveliness_subscriber", "liveliness_query", "query")
_SIGNATURE_HASH = hashes.SHA256()


class CredentialsError(AlicaError, ValueError):
    """A team's credentials that cannot be made or used: which file, what is wrong, and what to do."""


def _make_hint(folder: Path | str, names: Iterable[str]) -> str:
    return f"alica team keys --out {folder} --add {' '.join(names)}"


def check_name(name: object, *, agent: bool = True) -> str:
    """``name`` when it can name a process of a team (an agent; with ``agent=False`` also the center).

    Raises:
        CredentialsError: not a non-empty name of at most :data:`MAX_NAME` printable characters without
            ``/ * $ ? #`` or spaces, or a name the credentials use themselves (``ca``, and ``center`` for an agent).
    """
    if not isinstance(name, str) or not _NAME.fullmatch(name) or not name.isprintable() or len(name) > MAX_NAME:
        raise CredentialsError(
            f"a team member's name is a non-empty name of at most {MAX_NAME} printable characters without "
            f"'/', '*', '$', '?', '#' or spaces, got {name!r}"
        )
    if name == CA:
        raise CredentialsError(f"'{CA}' names the team's certificate authority (ca.pem): give the agent another name")
    if agent and name == CENTER:
        raise CredentialsError(
            f"'{CENTER}' names the control center, which always has keys: give the agent another name"
        )
    return name


# ---------------------------------------------------------------------------------------------- making keys


def _write(path: Path, data: bytes, mode: int) -> None:
    """Write ``data`` to ``path`` with permissions ``mode`` (also when the file was there)."""
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, mode)
    try:
        os.fchmod(fd, mode)
        os.write(fd, data)
    finally:
        os.close(fd)


def _write_key(path: Path, key: ec.EllipticCurvePrivateKey) -> None:
    pem = key.private_bytes(serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8, serialization.NoEncryption())
    _write(path, pem, 0o600)


def _write_cert(path: Path, cert: x509.Certificate) -> None:
    _write(path, cert.public_bytes(serialization.Encoding.PEM), 0o644)


def _now() -> datetime.datetime:
    return datetime.datetime.now(datetime.UTC)


def _make_ca(folder: Path, not_before: datetime.datetime, not_after: datetime.datetime) -> list[Path]:
    key = ec.generate_private_key(ec.SECP256R1())
    subject = x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, f"alica team CA {secrets.token_hex(8)}")])
    cert = (
        x509.CertificateBuilder()
        .subject_name(subject)
        .issuer_name(subject)
        .public_key(key.public_key())
        .serial_number(x509.random_serial_number())
        .not_valid_before(not_before)
        .not_valid_after(not_after)
        .add_extension(x509.BasicConstraints(ca=True, path_length=0), critical=True)
        .add_extension(
            x509.KeyUsage(
                digital_signature=False,
                content_commitment=False,
                key_encipherment=False,
                data_encipherment=False,
                key_agreement=False,
                key_cert_sign=True,
                crl_sign=True,
                encipher_only=False,
                decipher_only=False,
            ),
            critical=True,
        )
        .add_extension(x509.SubjectKeyIdentifier.from_public_key(key.public_key()), critical=False)
        .sign(key, hashes.SHA256())
    )
    _write_key(folder / f"{CA}.key", key)
    _write_cert(folder / f"{CA}.pem", cert)
    return [folder / f"{CA}.pem", folder / f"{CA}.key"]


def _issue(
    folder: Path, name: str, *, not_before: datetime.datetime | None = None, not_after: datetime.datetime
) -> list[Path]:
    """Write ``folder/name.pem`` and ``name.key``: a new key and its certificate signed by ``folder``'s CA.

    The certificate is valid from ``not_before`` to ``not_after``; without ``not_before``, from now (less
    :data:`SKEW`) and at most as long as the CA's. (Tests give ``not_before`` for certificates valid only in the past.)
    """
    ca_key_file, ca_file = folder / f"{CA}.key", folder / f"{CA}.pem"
    ca_cert = _read_cert(ca_file, "the team's CA certificate")
    ca_key = _read_key(
        ca_key_file,
        ca_cert,
        missing=f"no {ca_key_file}: only the holder of the team's CA key can add members; add them where it is",
        mismatch=f"{ca_key_file} is not the key of {ca_file}: is the folder damaged?",
    )
    key = ec.generate_private_key(ec.SECP256R1())
    dns = [x509.DNSName(name)] if _DNS_LABEL.fullmatch(name) else []
    if not_before is None:
        not_before = max(_now() - SKEW, ca_cert.not_valid_before_utc)
        not_after = min(not_after, ca_cert.not_valid_after_utc)
    cert = (
        x509.CertificateBuilder()
        .subject_name(x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, name)]))
        .issuer_name(ca_cert.subject)
        .public_key(key.public_key())
        .serial_number(x509.random_serial_number())
        .not_valid_before(not_before)
        .not_valid_after(not_after)
        .add_extension(x509.BasicConstraints(ca=False, path_length=None), critical=True)
        .add_extension(
            x509.KeyUsage(
                digital_signature=True,
                content_commitment=False,
                key_encipherment=False,
                data_encipherment=False,
                key_agreement=False,
                key_cert_sign=False,
                crl_sign=False,
                encipher_only=False,
                decipher_only=False,
            ),
            critical=True,
        )
        .add_extension(
            x509.ExtendedKeyUsage([ExtendedKeyUsageOID.SERVER_AUTH, ExtendedKeyUsageOID.CLIENT_AUTH]), critical=False
        )
        .add_extension(x509.SubjectAlternativeName([*dns, x509.DNSName("localhost")]), critical=False)
        .add_extension(x509.SubjectKeyIdentifier.from_public_key(key.public_key()), critical=False)
        .add_extension(
            x509.AuthorityKeyIdentifier.from_issuer_public_key(ca_cert.public_key()),  # type: ignore[arg-type]
            critical=False,
        )
        .sign(ca_key, hashes.SHA256())
    )
    _write_key(folder / f"{name}.key", key)
    _write_cert(folder / f"{name}.pem", cert)
    return [folder / f"{name}.pem", folder / f"{name}.key"]


def _write_roster(folder: Path, members: Iterable[str]) -> Path:
    path = folder / ROSTER
    text = json.dumps({"members": sorted(members), "center": CENTER}, indent=2) + "\n"
    _write(path, text.encode(), 0o644)
    return path


def make_keys(out: Path | str, names: Iterable[str], *, days: int = 365, add: bool = False) -> list[Path]:
    """Make a team's credentials in the folder ``out`` (see the module docstring), or add members to them.

    Args:
        out: the folder; a new team needs it missing or empty (it is made, readable by its owner only).
        names: the agents (each gets ``NAME.pem`` and ``NAME.key``; the center gets ``center.pem`` and
            ``center.key`` with a new team).
        days: how many days the new certificates are valid (for a new team, the CA's too; a member's
            certificate never outlives the CA's).
        add: add ``names`` to the team in ``out``, with its CA (``ca.key`` must be there); a name of the roster
            without a certificate there gets a new one (renewing a member's keys).

    Returns:
        The files written.

    Raises:
        CredentialsError: a bad name or number of days, a name given twice or with a certificate in ``out``, a folder
            that is not empty (without ``add``) or holds no team (with ``add``).
    """
    folder = Path(out)
    names = list(names)
    for name in names:
        check_name(name)
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise CredentialsError(f"{', '.join(twice)} named twice: give each agent once")
    if isinstance(days, bool) or not isinstance(days, int) or days < 1:
        raise CredentialsError(f"days must be a whole number of days >= 1, got {days!r}")
    if not names:
        raise CredentialsError("name at least one agent of the team, e.g. 'alica team keys --out keys a b'")
    not_after = _now() + datetime.timedelta(days=days)
    if folder.exists() and not folder.is_dir():
        raise CredentialsError(f"{folder} is a file, not a folder: give --out a new folder")
    if add:
        if not (folder / f"{CA}.key").is_file() or not (folder / ROSTER).is_file():
            raise CredentialsError(
                f"{folder} holds no team's credentials to add to (no {CA}.key or {ROSTER}); "
                f"make them with: alica team keys --out {folder} {' '.join(names)}"
            )
        members = _read_roster(folder)[0]
        already = sorted(n for n in names if (folder / f"{n}.pem").exists())
        if already:
            raise CredentialsError(
                f"{', '.join(already)} already hold(s) keys in {folder}: give new names (a member's keys are never "
                f"overwritten; to renew them, delete {already[0]}.pem and {already[0]}.key there first)"
            )
        written: list[Path] = []
        for name in names:
            written += _issue(folder, name, not_after=not_after)
        written.append(_write_roster(folder, members | set(names)))
        return written
    if folder.exists() and any(folder.iterdir()):
        raise CredentialsError(
            f"{folder} exists and is not empty: give a new folder, or add agents to the team there with: "
            f"{_make_hint(folder, names)}"
        )
    folder.mkdir(mode=0o700, parents=True, exist_ok=True)
    os.chmod(folder, 0o700)
    written = _make_ca(folder, _now() - SKEW, not_after)
    for name in [*names, CENTER]:
        written += _issue(folder, name, not_after=not_after)
    written.append(_write_roster(folder, names))
    return written


# ---------------------------------------------------------------------------------------------- loading keys


def _read_cert(path: Path, what: str) -> x509.Certificate:
    try:
        return x509.load_pem_x509_certificate(path.read_bytes())
    except FileNotFoundError:
        raise CredentialsError(f"no {path} ({what}): is this the folder 'alica team keys' made?") from None
    except ValueError as exc:
        raise CredentialsError(f"{path} ({what}) is not a PEM certificate ({exc}): copy it again") from None


def _read_roster(folder: Path) -> tuple[frozenset[str], str]:
    path = folder / ROSTER
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise CredentialsError(f"no {path} (the team's roster): copy it from where 'alica team keys' made it") from None
    except (ValueError, UnicodeDecodeError) as exc:
        raise CredentialsError(f"{path} is not JSON ({exc}): copy it again") from None
    members, center = (data.get("members"), data.get("center")) if isinstance(data, dict) else (None, None)
    if not isinstance(members, list) or not isinstance(center, str):
        raise CredentialsError(f'{path} is not a roster {{"members": [NAME, ...], "center": NAME}}: copy it again')
    try:
        return frozenset(check_name(m) for m in members), check_name(center, agent=False)
    except CredentialsError as exc:
        raise CredentialsError(f"{path}: {exc}") from None


def _read_key(path: Path, cert: x509.Certificate, *, missing: str, mismatch: str) -> ec.EllipticCurvePrivateKey:
    """The EC private key in ``path``, which must be ``cert``'s (``missing``, ``mismatch``: the errors' words)."""
    try:
        key = serialization.load_pem_private_key(path.read_bytes(), password=None)
    except FileNotFoundError:
        raise CredentialsError(missing) from None
    except (ValueError, TypeError) as exc:
        raise CredentialsError(f"{path} is not a PEM private key without a password ({exc})") from None
    if not isinstance(key, ec.EllipticCurvePrivateKey) or not _same_key(key.public_key(), cert):
        raise CredentialsError(mismatch)
    return key


def _same_key(public: object, cert: x509.Certificate) -> bool:
    if not isinstance(public, ec.EllipticCurvePublicKey):
        return False
    der = serialization.Encoding.DER, serialization.PublicFormat.SubjectPublicKeyInfo
    return public.public_bytes(*der) == cert.public_key().public_bytes(*der)


def _common_name(cert: x509.Certificate) -> str | None:
    names = cert.subject.get_attributes_for_oid(NameOID.COMMON_NAME)
    value = names[0].value if len(names) == 1 else None
    return value if isinstance(value, str) else None


def _issued_by(cert: x509.Certificate, ca: x509.Certificate) -> bool:
    try:
        cert.verify_directly_issued_by(ca)
    except (ValueError, TypeError, InvalidSignature):
        return False
    return True


def _date(moment: datetime.datetime) -> str:
    return moment.strftime("%Y-%m-%d %H:%M UTC")


def _check_valid(cert: x509.Certificate, path: Path, hint: str) -> None:
    now = _now()
    if now > cert.not_valid_after_utc:
        raise CredentialsError(f"{path} expired on {_date(cert.not_valid_after_utc)}; {hint}")
    if now < cert.not_valid_before_utc:
        raise CredentialsError(
            f"{path} is valid only from {_date(cert.not_valid_before_utc)} (is this host's clock right?); {hint}"
        )


@dataclass(frozen=True)
class TeamKeys:
    """One process's credentials in its team: its certificate and key, the team's CA and roster.

    Make it with :meth:`load`, which checks the files.

    Attributes:
        folder: the folder of the credentials.
        name: the process's identity (an agent's name, or :data:`CENTER`).
        ca: the team's CA certificate.
        cert: the process's certificate.
        key: the process's private key.
        members: the team's agents (the roster, without the center).
        center: the control center's identity.
    """

    folder: Path
    name: str
    ca: Path
    cert: Path
    key: Path
    members: frozenset[str]
    center: str
    _private: list[ec.EllipticCurvePrivateKey] = field(default_factory=list, repr=False, compare=False)
    _signers: dict[str, x509.Certificate | None] = field(default_factory=dict, repr=False, compare=False)
    _lock: threading.Lock = field(default_factory=threading.Lock, repr=False, compare=False)

    @classmethod
    def load(cls, folder: Path | str, name: str) -> TeamKeys:
        """The credentials of ``name`` in ``folder``, checked.

        Raises:
            CredentialsError: a file missing or not parsing; a certificate that is not ``name``'s, not signed by
                the team's CA, not valid now, or whose key is not in ``name.key``; ``name`` not in the roster.
        """
        folder = Path(folder)
        if not folder.is_dir():
            raise CredentialsError(
                f"no folder {folder} of team credentials: make them with: alica team keys --out {folder} NAME..."
            )
        check_name(name, agent=False)
        members, center = _read_roster(folder)
        if name != center and name not in members:
            raise CredentialsError(
                f"'{name}' is not in the team's roster ({folder / ROSTER}: {', '.join(sorted(members))}); "
                f"add it with: {_make_hint(folder, [name])}"
            )
        ca_file = folder / f"{CA}.pem"
        ca = _read_cert(ca_file, "the team's CA certificate")
        _check_valid(ca, ca_file, "the team needs new credentials: alica team keys --out NEW_DIR NAME...")
        who = "the control center" if name == center else f"agent '{name}'"
        cert_file, key_file = folder / f"{name}.pem", folder / f"{name}.key"
        if not cert_file.is_file():
            raise CredentialsError(
                f"no certificate for {who} in {folder}/ ({cert_file}); make one with: {_make_hint(folder, [name])}"
            )
        cert = _read_cert(cert_file, f"the certificate of {who}")
        if _common_name(cert) != name:
            raise CredentialsError(
                f"{cert_file} is the certificate of '{_common_name(cert)}', not of '{name}': copy {name}.pem again"
            )
        if not _issued_by(cert, ca):
            raise CredentialsError(
                f"{cert_file} is not signed by the team's CA ({ca_file}): it belongs to another team's credentials; "
                f"copy {name}.pem and {CA}.pem from the same folder made by alica team keys"
            )
        _check_valid(
            cert,
            cert_file,
            f"renew it where the team's {CA}.key is: delete {name}.pem and {name}.key there, then run "
            f"{_make_hint(folder, [name])}",
        )
        private = _read_key(
            key_file,
            cert,
            missing=f"no private key for {who} in {folder}/ ({key_file}): copy {name}.key with {name}.pem",
            mismatch=f"{key_file} is not the key of {cert_file}: copy both from the same folder",
        )
        keys = cls(folder, name, ca_file, cert_file, key_file, members, center)
        keys._private.append(private)
        keys._signers[name] = cert
        return keys

    # ------------------------------------------------------------------------------------------ signatures

    def sign(self, data: bytes) -> bytes:
        """The signature of ``data`` with this process's key (ECDSA P-256 with SHA-256, DER)."""
        if not self._private:
            private = serialization.load_pem_private_key(self.key.read_bytes(), password=None)
            if not isinstance(private, ec.EllipticCurvePrivateKey):
                raise CredentialsError(f"{self.key} is not an EC private key")
            self._private.append(private)
        return self._private[0].sign(bytes(data), ec.ECDSA(_SIGNATURE_HASH))

    def verifies(self, signer: object, data: object, signature: object) -> bool:
        """Whether ``signature`` is ``signer``'s of ``data``; ``signer`` must be in the team and hold a certificate
        of its CA, valid now (``folder/SIGNER.pem``, read once).

        Never raises: anything that is not such a signature (of any type or size) is ``False``.
        """
        try:
            if not isinstance(signer, str) or not isinstance(data, bytes | bytearray):
                return False
            if not isinstance(signature, bytes | bytearray) or not 0 < len(signature) <= MAX_SIGNATURE:
                return False
            if signer != self.center and signer not in self.members:
                return False
            cert = self._signer(signer)
            if cert is None or not cert.not_valid_before_utc <= _now() <= cert.not_valid_after_utc:
                return False
            public = cert.public_key()
            if not isinstance(public, ec.EllipticCurvePublicKey):
                return False
            public.verify(bytes(signature), bytes(data), ec.ECDSA(_SIGNATURE_HASH))
        except Exception:  # InvalidSignature, and whatever a hostile input could make the parser raise
            return False
        return True

    def _signer(self, signer: str) -> x509.Certificate | None:
        """``signer``'s certificate when it is the team's (its name, signed by the CA); ``None`` if not."""
        with self._lock:
            if signer in self._signers:
                return self._signers[signer]
            cert: x509.Certificate | None
            try:
                ca = x509.load_pem_x509_certificate(self.ca.read_bytes())
                cert = x509.load_pem_x509_certificate((self.folder / f"{signer}.pem").read_bytes())
                if _common_name(cert) != signer or not _issued_by(cert, ca):
                    cert = None
            except (OSError, ValueError):
                cert = None
            self._signers[signer] = cert
            return cert

    # ------------------------------------------------------------------------------------------ zenoh

    def zenoh_settings(self, prefix: str) -> dict[str, object]:
        """zenoh's TLS (with mutual authentication) and access control for this process in the team under ``prefix``.

        Returns:
            zenoh key path -> JSON-able value, for the ``extra`` of :func:`alica.comm.zenoh_transport.zenoh_config`
            (the session's endpoints must be ``tls/``, see :func:`tls_endpoint`).

        Raises:
            CredentialsError: ``prefix`` is not a key prefix (a name without ``/ * $ ? #`` or spaces).
        """
        if not isinstance(prefix, str) or not _NAME.fullmatch(prefix):
            raise CredentialsError(
                f"a key prefix is a non-empty name without '/', '*', '$', '?', '#' or spaces: {prefix!r}"
            )
        ca, cert, key = (str(p.resolve()) for p in (self.ca, self.cert, self.key))
        acl = self._viewer_acl(prefix) if self.name == self.center else self._member_acl(prefix)
        acl["rules"].append(_rule("egress", "egress", ZENOH_MESSAGES, ["**"]))
        acl["subjects"].append({"id": "everyone"})  # (a subject of no attributes: every link)
        acl["policies"].append({"id": "egress", "rules": ["egress"], "subjects": ["everyone"]})
        return {
            "transport/link/tls/root_ca_certificate": ca,
            "transport/link/tls/listen_private_key": key,
            "transport/link/tls/listen_certificate": cert,
            "transport/link/tls/connect_private_key": key,
            "transport/link/tls/connect_certificate": cert,
            "transport/link/tls/enable_mtls": True,
            "transport/link/tls/verify_name_on_connect": False,
            "access_control": {"enabled": True, "default_permission": "deny", **acl},
        }

    def _member_acl(self, p: str) -> dict[str, list[dict[str, object]]]:
        """A member's ingress: each member's own keys from its link, the team's declarations and commands from all."""
        ordered = sorted(self.members)
        rules = [
            _rule("operator", "ingress", ["put"], [f"{p}/center/operator"]),
            _rule("declarations", "ingress", _DECLARATIONS, [f"{p}/**"]),
        ]
        subjects: list[dict[str, object]] = [{"id": "team", "cert_common_names": [*ordered, self.center]}]
        policies: list[dict[str, object]] = [
            {"id": "team", "rules": ["operator", "declarations"], "subjects": ["team"]}
        ]
        for i, m in enumerate(ordered):  # (ids by number: a name need not suit zenoh's ids)
            own = [f"put-{i}", f"token-{i}", f"queryable-{i}"]
            rules += [
                _rule(own[0], "ingress", ["put"], [f"{p}/m/{m}/**", f"{p}/hb/{m}", f"{p}/center/events/{m}"]),
                _rule(own[1], "ingress", ["liveliness_token"], [f"{p}/alive/{m}", f"{p}/alive/{m}/*"]),
                _rule(own[2], "ingress", ["declare_queryable", "reply"], [f"{p}/hist/{m}", f"{p}/center/history/{m}"]),
            ]
            subjects.append({"id": f"member-{i}", "cert_common_names": [m]})
            policies.append({"id": f"member-{i}", "rules": own, "subjects": [f"member-{i}"]})
        return {"rules": rules, "subjects": subjects, "policies": policies}

    def _viewer_acl(self, p: str) -> dict[str, list[dict[str, object]]]:
        """The center's ingress: what any member forwards to a viewer (events, answers, tokens, declarations)."""
        rules = [
            _rule("events", "ingress", ["put"], [f"{p}/center/events/*"]),
            _rule("answers", "ingress", ["reply"], [f"{p}/center/history/*", f"{p}/hist/*"]),
            _rule("tokens", "ingress", ["liveliness_token"], [f"{p}/alive/**"]),
            _rule(
                "declarations",
                "ingress",
                ["declare_subscriber", "declare_queryable", "declare_liveliness_subscriber"],
                [f"{p}/**"],
            ),
        ]
        subjects: list[dict[str, object]] = [{"id": "members", "cert_common_names": sorted(self.members)}]
        policies: list[dict[str, object]] = [
            {"id": "members", "rules": ["events", "answers", "tokens", "declarations"], "subjects": ["members"]}
        ]
        return {"rules": rules, "subjects": subjects, "policies": policies}


def _rule(rule_id: str, flow: str, messages: Iterable[str], key_exprs: list[str]) -> dict[str, object]:
    return {"id": rule_id, "permission": "allow", "flows": [flow], "messages": list(messages), "key_exprs": key_exprs}


def tls_endpoint(endpoint: str) -> str:
    """``endpoint`` as a TLS endpoint: ``tcp/HOST:PORT`` becomes ``tls/HOST:PORT``; ``tls/...`` stays.

    Raises:
        ValueError: an endpoint of another protocol (``udp/``, ``unixsock-stream/``...), which has no TLS.
    """
    if not isinstance(endpoint, str) or "/" not in endpoint:
        raise ValueError(f"a zenoh endpoint looks like 'tls/127.0.0.1:7447', got {endpoint!r}")
    proto, _, rest = endpoint.partition("/")
    if proto == "tls":
        return endpoint
    if proto == "tcp":
        return f"tls/{rest}"
    raise ValueError(
        f"with team credentials the links are TLS over TCP: {endpoint} ({proto}) cannot be; use tls/HOST:PORT"
    )
