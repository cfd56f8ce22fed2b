"""Training, evaluation, comparison and the ``motiongym`` command."""
