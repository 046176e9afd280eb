"""serialspec: serial device protocols described in YAML, compiled to codecs, structs, messages and docs.

The pipeline, one module per stage:

    spec.loader   YAML text -> plain values, each remembered with its file:line:column
    spec.resolve  plain values -> validated, fully resolved immutable model (spec.model), by spec.passes
    emit.*        model -> generated files, one target per folder (emit.python, emit.markdown; emit.common shared)
    checksums     the checksum algorithms, one module each (generated code imports their runtime functions)
    runtime       the small hand-written library that generated code imports
    cli           one module per verb of the `serialspec` command
"""

__version__ = "0.1.0"
