"""Allow ``python -m servostudio``."""

from servostudio.cli import main

raise SystemExit(main())
