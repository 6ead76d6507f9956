"""Episodes, metrics, failure taxonomy and reports."""
