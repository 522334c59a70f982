import os

# Let scikit-learn's array-API estimator checks run instead of skipping (must precede scipy).
os.environ.setdefault("SCIPY_ARRAY_API", "1")
