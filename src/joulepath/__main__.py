"""``python -m joulepath``."""

from joulepath.cli import main

raise SystemExit(main())
