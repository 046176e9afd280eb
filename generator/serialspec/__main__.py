import sys

from serialspec.cli import main

sys.exit(main())
