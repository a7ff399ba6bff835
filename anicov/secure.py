"""A secure profile for a team: a test CA, per-process certificates, Zenoh configs with mutual TLS
and access control (``anicov certs``).

Every process of the team gets its own key and certificate, signed by one CA,
with its role as the certificate's common name (``router``, ``coordinator``,
``logger``, ``agent-0`` …). The router accepts only TLS links whose client
presents a certificate of that CA (mutual TLS), and its access-control list
lets each process publish only what its role publishes:

- ``agent-i``: its own ``agent/i/…`` keys (delta, state, history) and its
  liveliness token ``alive/agent/i``;
- ``coordinator``: ``coordinator/…`` (go, objectives, snapshot, history) and
  ``run/…`` (the end of the run, progress);
- ``logger``: only its liveliness token;
- every member may subscribe to and query anything of the team.

Anything else (another team, a spoofed agent, a process without a
certificate) is denied: the default permission is ``deny``. The CA made here
is for tests and labs; a fleet would use its own PKI with the same names.
"""

from __future__ import annotations

import datetime
import ipaddress
import json
from dataclasses import dataclass
from pathlib import Path

from cryptography import x509
from cryptography.hazmat.primitives import hashes, serialization
from cryptography.hazmat.primitives.asymmetric import ec
from cryptography.x509.oid import ExtendedKeyUsageOID, NameOID

from protocol.keys import ROOT, check_team_name

DEFAULT_HOSTS = ("localhost", "127.0.0.1")
DEFAULT_ENDPOINT = "tls/localhost:7447"
PROFILE_FILE = "profile.json"

_READ = ["declare_subscriber", "query", "declare_liveliness_subscriber", "liveliness_query"]
_DELIVER = ["put", "delete", "reply", "declare_queryable", "liveliness_token"]
_PUBLISH = ["put", "delete", "declare_queryable", "reply", "liveliness_token"]


@dataclass(frozen=True)
class Profile:
    """Where ``make_profile`` wrote what."""

    directory: Path
    roles: tuple[str, ...]

    def config(self, role: str) -> Path:
        return self.directory / f"{role}.json5"

    def certificate(self, role: str) -> Path:
        return self.directory / f"{role}.pem"

    @property
    def ca(self) -> Path:
        return self.directory / "ca.pem"


def roles_of(agents: int) -> tuple[str, ...]:
    return ("router", "coordinator", "logger", *(f"agent-{i}" for i in range(agents)))


def access_control(team: str, agents: int) -> dict[str, object]:
    """The router's access-control list: read for every member, publish only one's own keys."""
    prefix = f"{ROOT}/{check_team_name(team)}"
    members = [role for role in roles_of(agents) if role != "router"]
    rules: list[dict[str, object]] = [
        _rule("team-reads", _READ, ["ingress", "egress"], [f"{prefix}/**"]),
        _rule("team-receives", _DELIVER, ["egress"], [f"{prefix}/**"]),
        _rule(
            "coordinator-publishes",
            _PUBLISH,
            ["ingress"],
            [f"{prefix}/coordinator/**", f"{prefix}/run/**", f"{prefix}/alive/coordinator/*"],
        ),
        _rule("logger-publishes", ["liveliness_token"], ["ingress"], [f"{prefix}/alive/logger/*"]),
    ]
    subjects: list[dict[str, object]] = [{"id": "members", "cert_common_names": members}]
    policies: list[dict[str, object]] = [{"rules": ["team-reads", "team-receives"], "subjects": ["members"]}]
    for role in ("coordinator", "logger"):
        subjects.append({"id": role, "cert_common_names": [role]})
        policies.append({"rules": [f"{role}-publishes"], "subjects": [role]})
    for agent in range(agents):
        name = f"agent-{agent}"
        rules.append(
            _rule(
                f"{name}-publishes",
                _PUBLISH,
                ["ingress"],
                [f"{prefix}/agent/{agent}/**", f"{prefix}/alive/agent/{agent}"],
            )
        )
        subjects.append({"id": name, "cert_common_names": [name]})
        policies.append({"rules": [f"{name}-publishes"], "subjects": [name]})
    return {
        "enabled": True,
        "default_permission": "deny",
        "rules": rules,
        "subjects": subjects,
        "policies": policies,
    }


def _rule(ident: str, messages: list[str], flows: list[str], key_exprs: list[str]) -> dict[str, object]:
    return {"id": ident, "permission": "allow", "messages": messages, "flows": flows, "key_exprs": key_exprs}


def zenoh_profile_config(role: str, directory: Path, endpoint: str, team: str, agents: int) -> dict[str, object]:
    """The Zenoh config of one role: the router listens, everyone else connects, all over mutual TLS."""
    tls: dict[str, object] = {"root_ca_certificate": str(directory / "ca.pem"), "enable_mtls": True}
    config: dict[str, object] = {"scouting": {"multicast": {"enabled": False}, "delay": 0}}
    if role == "router":
        tls |= {
            "listen_private_key": str(directory / "router.key"),
            "listen_certificate": str(directory / "router.pem"),
        }
        config |= {
            "mode": "router",
            "listen": {"endpoints": [endpoint]},
            "access_control": access_control(team, agents),
        }
    else:
        tls |= {
            "connect_private_key": str(directory / f"{role}.key"),
            "connect_certificate": str(directory / f"{role}.pem"),
        }
        config |= {"mode": "client", "connect": {"endpoints": [endpoint]}}
    # Only TLS: a plain-TCP endpoint in a config by mistake must not open an unauthenticated door.
    config["transport"] = {"link": {"protocols": ["tls"], "tls": tls}}
    return config


def make_profile(
    directory: Path,
    agents: int,
    team: str = "team",
    hosts: tuple[str, ...] = DEFAULT_HOSTS,
    endpoint: str = DEFAULT_ENDPOINT,
    days: int = 365,
) -> Profile:
    """Write a CA, a key and certificate per role, and a Zenoh config per role into ``directory``."""
    if agents < 1:
        raise ValueError(f"agents: expected a team size of at least 1, got {agents}")
    if not endpoint.startswith("tls/"):
        raise ValueError(f"endpoint: expected a tls/HOST:PORT endpoint, got {endpoint!r}")
    check_team_name(team)
    directory = directory.resolve()
    directory.mkdir(parents=True, exist_ok=True)
    now = datetime.datetime.now(datetime.UTC)
    valid = (now - datetime.timedelta(minutes=5), now + datetime.timedelta(days=days))
    ca_key = ec.generate_private_key(ec.SECP256R1())
    ca_name = x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, f"anicov test CA ({team})")])
    ca_cert = (
        _builder(ca_name, ca_name, ca_key.public_key(), valid)
        .add_extension(x509.BasicConstraints(ca=True, path_length=0), critical=True)
        .add_extension(x509.KeyUsage(False, False, False, False, False, True, True, False, False), critical=True)
        .sign(ca_key, hashes.SHA256())
    )
    _write_key(directory / "ca.key", ca_key)
    (directory / "ca.pem").write_bytes(ca_cert.public_bytes(serialization.Encoding.PEM))
    alt_names = [_alt_name(host) for host in hosts]
    roles = roles_of(agents)
    for role in roles:
        key = ec.generate_private_key(ec.SECP256R1())
        name = x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, role)])
        cert = (
            _builder(name, ca_name, key.public_key(), valid)
            .add_extension(x509.BasicConstraints(ca=False, path_length=None), critical=True)
            .add_extension(x509.SubjectAlternativeName(alt_names), critical=False)
            .add_extension(
                x509.ExtendedKeyUsage([ExtendedKeyUsageOID.SERVER_AUTH, ExtendedKeyUsageOID.CLIENT_AUTH]),
                critical=False,
            )
            .sign(ca_key, hashes.SHA256())
        )
        _write_key(directory / f"{role}.key", key)
        (directory / f"{role}.pem").write_bytes(cert.public_bytes(serialization.Encoding.PEM))
        config = zenoh_profile_config(role, directory, endpoint, team, agents)
        (directory / f"{role}.json5").write_text(
            f"// anicov secure profile: {role} of team {team!r} ({agents} agents). Made by 'anicov certs'.\n"
            + json.dumps(config, indent=2)
            + "\n",
            encoding="utf-8",
        )
    (directory / PROFILE_FILE).write_text(
        json.dumps({"team": team, "agents": agents, "endpoint": endpoint, "hosts": list(hosts)}, indent=2) + "\n"
    )
    return Profile(directory, roles)


def load_profile(directory: Path, team: str, agents: int) -> tuple[Profile, str]:
    """A profile made for this team and at least this many agents, and its endpoint; else a clear error."""
    facts_path = directory / PROFILE_FILE
    if not facts_path.is_file():
        raise ValueError(
            f"--secure {directory}: no {PROFILE_FILE} there; make one with 'anicov certs --out {directory}'"
        )
    facts = json.loads(facts_path.read_text())
    if facts.get("team") != team:
        raise ValueError(f"--secure {directory}: made for team {facts.get('team')!r}, expected --team {team!r}")
    if int(facts.get("agents", 0)) < agents:
        raise ValueError(
            f"--secure {directory}: has certificates for {facts.get('agents')} agents, expected >= {agents}"
        )
    profile = Profile(directory.resolve(), roles_of(agents))
    missing = [str(profile.config(role)) for role in profile.roles if not profile.config(role).is_file()]
    if missing:
        raise ValueError(f"--secure {directory}: missing {', '.join(missing)}")
    return profile, str(facts["endpoint"])


def _builder(
    subject: x509.Name, issuer: x509.Name, public_key: ec.EllipticCurvePublicKey, valid: tuple[datetime.datetime, ...]
) -> x509.CertificateBuilder:
    return (
        x509.CertificateBuilder()
        .subject_name(subject)
        .issuer_name(issuer)
        .public_key(public_key)
        .serial_number(x509.random_serial_number())
        .not_valid_before(valid[0])
        .not_valid_after(valid[1])
    )


def _alt_name(host: str) -> x509.GeneralName:
    try:
        return x509.IPAddress(ipaddress.ip_address(host))
    except ValueError:
        return x509.DNSName(host)


def _write_key(path: Path, key: ec.EllipticCurvePrivateKey) -> None:
    path.touch(mode=0o600, exist_ok=True)
    path.chmod(0o600)  # a private key readable by others is no key
    path.write_bytes(
        key.private_bytes(serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8, serialization.NoEncryption())
    )
