"""Air stage (OpenFOAM steady air field and its one-way action on particles).

Not built yet: a case asks for it with ``air.model = "uniform"`` or ``"cfd"``, and until this
stage exists :func:`drumflow.pipeline.run_case` refuses such a case before any solver starts.
"""
