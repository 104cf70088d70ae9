"""Print the README's N-th command for a fresh machine (its ``sh setup`` blocks: 1, the main
job; 2, the tests), so that CI runs the README's commands as written, not a copy of them."""

import re
import sys
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"
blocks = re.findall(r"^```sh setup\n(.*?)^```", README.read_text(), flags=re.S | re.M)
print(blocks[int(sys.argv[1]) - 1].strip())
