"""The scene-key reference (mbcontrol/scene/reference.py) is the parser's own account: every
key a section allows is listed with a meaning, no meaning names a key the parser refuses, the
recorder leaves no trace, and the README's "Scene keys" section is the current output."""
import pytest

from tests.helpers import readme
from mbcontrol.errors import SceneError
from mbcontrol.scene import load_scene, reference
from mbcontrol.scene.checks import Reader


@pytest.fixture(scope="module")
def schema():
    return reference.schema()


def test_every_allowed_key_has_a_meaning_and_every_meaning_a_key(schema):
    allowed = {(s, k) for s, keys in schema.items() for k, w in keys.items() if w.get("allowed")}
    assert set(reference.SECTIONS) - {"identify"} == {s for s, _ in allowed}
    assert allowed - set(reference.MEANING) == set(), "keys the reference does not explain"
    assert set(reference.MEANING) - allowed == set(), "meanings of keys the parser refuses"
    assert Reader.record is None


def test_what_it_records_is_what_the_parser_does(schema, tmp_path):
    """Spot checks against the parser's behaviour, not against the recorder: a default the
    reference shows is the value a scene without the key gets, and a key it shows as
    required is refused when missing."""
    sphere = (readme.ROOT / "models" / "sphere.toml").read_text()
    (tmp_path / "sphere.toml").write_text(sphere.replace("rho = 1000.0\n", ""))
    assert load_scene(tmp_path / "sphere.toml").water.rho == schema["water"]["rho"]["default"]
    scene = load_scene("hinged_barge")
    assert scene.ptos[0].efficiency == schema["pto"]["efficiency"]["default"] == 1.0
    assert scene.hydro.lid is schema["hydro"]["lid"]["default"] is True
    assert schema["body"]["mass"]["required"]
    (tmp_path / "sphere.toml").write_text(sphere.replace("mass = 261724.0\n", ""))
    with pytest.raises(SceneError, match=r"body\[0\]\.mass: missing required field"):
        load_scene(tmp_path / "sphere.toml")
    assert schema["pto"]["preload"]["options"] == ("none", "balance")
    assert schema["mooring"]["EA"]["required"] and "anchor" in schema["mooring"]


def test_the_keys_command_prints_it_and_rewrites_a_readme(capsys, tmp_path):
    from mbcontrol.cli import main
    assert main(["keys"]) == 0 and capsys.readouterr().out == reference.markdown()
    stale = tmp_path / "README.md"
    stale.write_text("intro\n" + reference.BEGIN + "old\n" + reference.END + "\nrest\n")
    assert main(["keys", "--readme", str(stale)]) == 0
    assert stale.read_text() == ("intro\n" + reference.BEGIN + reference.markdown()
                                 + reference.END + "\nrest\n")


def test_the_readme_section_is_current():
    text = readme.text()
    assert reference.in_readme(text) == text, \
        "README's Scene keys section is stale: mbcontrol keys --readme"
