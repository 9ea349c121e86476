"""The README's Python examples run as written, and its set-up commands are the ones CI uses."""

import re
from pathlib import Path

README = Path(__file__).resolve().parents[2] / "README.md"


def test_readme_python_blocks_run(capsys):
    text = README.read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) >= 2
    ns: dict = {}
    for b in blocks:
        if "Viewer(" in b:  # needs a browser session; the viewer tests cover it
            continue
        exec(compile(b, "README.md", "exec"), ns)
    assert "arm" in ns and "sols" in ns and ns["sols"].solutions.shape[0] >= 1
    assert ns["res"].success


def test_readme_has_the_two_setup_commands():
    text = README.read_text()
    main = re.search(r"<!-- main-command -->\n```bash\n(.*?)\n```", text, re.S).group(1)
    test = re.search(r"<!-- test-command -->\n```bash\n(.*?)\n```", text, re.S).group(1)
    assert "anthroarm check" in main and "pip install" in main and " -e . " in main
    assert "pytest" in test and '".[test]"' in test
    # the getting-started page shows the same two commands, word for word
    guide = (README.parent / "docs" / "getting_started.md").read_text()
    assert main in guide and test in guide
    ci = (README.parent / ".ci" / "run").read_text()
    assert "test-command" in ci  # .ci/run executes exactly the README's test command
