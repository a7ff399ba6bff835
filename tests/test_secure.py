"""The secure profile: certificates, mutual TLS and access control, with a real router and real sessions."""

from __future__ import annotations

import json
import stat

import pytest
import zenoh
from cryptography import x509
from cryptography.hazmat.primitives.asymmetric import ec

from anicov.secure import access_control, load_profile, make_profile
from protocol.session import zenoh_config
from tests.teamrun import anicov, free_port, launcher_command, processes_of, run, unique_team, wait_for, write_scenario

TEAM = unique_team()  # one per run: processes_of looks machine-wide, and another suite may run the same test


@pytest.fixture(scope="module")
def profile(tmp_path_factory):
    return make_profile(tmp_path_factory.mktemp("profile"), agents=2, team=TEAM)


@pytest.fixture(scope="module")
def router(profile):
    endpoint = f"tls/127.0.0.1:{free_port()}"
    session = zenoh.open(zenoh_config(listen=[endpoint], config_file=str(profile.config("router"))))
    yield endpoint
    session.close()


def client(profile_dir, role: str, endpoint: str) -> zenoh.Session:
    return zenoh.open(zenoh_config(connect=[endpoint], config_file=str(profile_dir / f"{role}.json5")))


def test_every_certificate_is_signed_by_the_ca_and_names_its_role(profile):
    ca = x509.load_pem_x509_certificate(profile.ca.read_bytes())
    for role in profile.roles:
        cert = x509.load_pem_x509_certificate(profile.certificate(role).read_bytes())
        assert cert.subject.get_attributes_for_oid(x509.NameOID.COMMON_NAME)[0].value == role
        cert.verify_directly_issued_by(ca)  # raises if the signature or issuer is wrong
        key_path = profile.directory / f"{role}.key"
        assert stat.S_IMODE(key_path.stat().st_mode) == 0o600
        assert isinstance(cert.public_key(), ec.EllipticCurvePublicKey)
    assert load_profile(profile.directory, TEAM, 2)[1] == "tls/localhost:7447"


def test_access_control_denies_by_default_and_gives_each_agent_only_its_keys():
    acl = access_control("lab", agents=3)
    assert acl["default_permission"] == "deny"
    rules = {rule["id"]: rule for rule in acl["rules"]}
    assert rules["agent-1-publishes"]["key_exprs"] == ["anicov/lab/agent/1/**", "anicov/lab/alive/agent/1"]
    assert rules["agent-1-publishes"]["flows"] == ["ingress"]
    publishers = {policy["rules"][0]: policy["subjects"] for policy in acl["policies"] if len(policy["rules"]) == 1}
    assert publishers["coordinator-publishes"] == ["coordinator"]
    assert publishers["agent-2-publishes"] == ["agent-2"]


def test_a_profile_for_another_team_or_a_smaller_team_is_refused(profile):
    with pytest.raises(ValueError, match=f"made for team '{TEAM}', expected --team 'other'"):
        load_profile(profile.directory, "other", 2)
    with pytest.raises(ValueError, match="certificates for 2 agents, expected >= 3"):
        load_profile(profile.directory, TEAM, 3)


def test_a_client_without_a_certificate_cannot_join(profile, router):
    bare = zenoh.Config.from_json5(
        json.dumps(
            {
                "mode": "client",
                "connect": {"endpoints": [router]},
                "scouting": {"multicast": {"enabled": False}},
                "transport": {"link": {"tls": {"root_ca_certificate": str(profile.ca)}}},
            }
        )
    )
    with pytest.raises(zenoh.ZError):
        zenoh.open(bare)


def test_a_client_with_a_certificate_from_another_ca_cannot_join(tmp_path, router):
    rogue = make_profile(tmp_path / "rogue", agents=2, team=TEAM)
    with pytest.raises(zenoh.ZError):
        client(rogue.directory, "agent-0", router)


def test_plain_tcp_is_not_accepted_on_the_tls_port(router):
    with pytest.raises(zenoh.ZError):
        zenoh.open(zenoh_config(connect=[router.replace("tls/", "tcp/")]))


def test_an_agent_cannot_publish_as_another_agent_or_as_the_coordinator(profile, router):
    received: list[tuple[str, bytes]] = []
    own_step, own_token = f"anicov/{TEAM}/agent/1/step", f"anicov/{TEAM}/alive/agent/1"
    with (
        client(profile.directory, "coordinator", router) as coordinator,
        client(profile.directory, "agent-1", router) as agent,
    ):
        coordinator.declare_subscriber(
            f"anicov/{TEAM}/**", lambda sample: received.append((str(sample.key_expr), sample.payload.to_bytes()))
        )
        # The subscription reaches the router when a probe on the agent's own key comes through.
        assert wait_for(lambda: (agent.put(own_step, b"probe"), (own_step, b"probe") in received)[1], timeout=60)
        for key in ("agent/0/step", "agent/0/history", "coordinator/go", "coordinator/objectives", "run/control"):
            agent.put(f"anicov/{TEAM}/{key}", b"spoofed")
        spoofed_token = agent.liveliness().declare_token(f"anicov/{TEAM}/alive/agent/0")  # kept: undeclared if dropped
        # After the spoofs, on the same link: once these are through, so is any spoof the router let pass.
        agent.put(own_step, b"own")
        token = agent.liveliness().declare_token(own_token)
        assert wait_for(lambda: (own_step, b"own") in received, timeout=60)

        def tokens() -> list[str]:
            return [
                str(reply.ok.key_expr) for reply in coordinator.liveliness().get(f"anicov/{TEAM}/alive/**") if reply.ok
            ]

        assert wait_for(lambda: own_token in tokens(), timeout=60)
        alive = tokens()
        token.undeclare()
        spoofed_token.undeclare()
    assert [key for key, payload in received if payload != b"probe"] == [own_step]
    assert f"anicov/{TEAM}/alive/agent/0" not in alive


def test_a_secure_team_runs_to_completion_and_equals_the_engine(tmp_path, profile):
    config = write_scenario(tmp_path / "s.toml", domain=[40.0, 40.0], agents=2, seed=3)
    engine = anicov("run", "--config", str(config), "--out", str(tmp_path / "engine"), "--quiet", "--no-record")
    assert engine.returncode == 0, engine.stderr
    command = launcher_command(
        "--config", str(config), "--out", str(tmp_path / "team"), "--secure", str(profile.directory), team=TEAM
    )
    command[command.index("--listen") + 1] = f"tls/127.0.0.1:{free_port()}"
    launched = run(command)
    assert launched.returncode == 0, launched.stderr + launched.stdout
    for name in ("trajectory.csv", "summary.json"):
        assert (tmp_path / "engine" / name).read_bytes() == (tmp_path / "team" / name).read_bytes(), name
    counts = json.loads((tmp_path / "team" / "coordinator_counts.json").read_text())
    assert counts["rejected"] == 0
    assert processes_of(TEAM) == []


def test_launcher_refuses_a_profile_of_another_team(tmp_path, profile):
    launched = run(launcher_command("--secure", str(profile.directory), "--out", str(tmp_path / "x"), team="other"))
    assert launched.returncode == 2
    assert f"made for team '{TEAM}', expected --team 'other'" in launched.stderr
