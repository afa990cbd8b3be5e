"""``python3 -m elastic``: the batch runner (see elastic.batch)."""

from .batch import main

raise SystemExit(main())
