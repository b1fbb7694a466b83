import sys

from dcfkit.cli import main

sys.exit(main())
