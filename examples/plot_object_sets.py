"""
Learning on sets of objects
===========================

Each sample here is a set of objects, a variable number of rows ``[x, y, type]``, and the
target counts some of them: :func:`boxtrees.make_box_regression` adds +100 for every object
of type 0 ("coins") and -300 for every object of type 1 ("enemies") inside a small square
near ``(0, 1)``; types 2 and 3 are distractors. No feature engineering is needed: the
forest's node tests count the objects of one type inside a box.

We fit a :class:`~boxtrees.BoxExtraTreesRegressor`, check its predictions on held-out sets,
and ask which object types (:func:`~boxtrees.type_importance`) and which regions
(:func:`~boxtrees.region_importance`) it relies on.
"""

import matplotlib.pyplot as plt
import numpy as np

from boxtrees import (BoxExtraTreesClassifier, BoxExtraTreesRegressor,
                      make_box_regression, region_importance, type_importance)

# %%
# The data
# --------
# 1,500 sets of about 16 objects each in ``[-10, 10]^2``; the first 1,000 train, the rest
# test. ``X`` is an :class:`~boxtrees.ObjectSets`: one array of object rows plus offsets,
# indexable and sliceable like a list of sets.
X, y = make_box_regression(1500, random_state=0)
X_train, y_train, X_test, y_test = X[:1000], y[:1000], X[1000:], y[1000:]
print(f"{len(X)} sets, {X.data.shape[0]} objects")
print("the first rows of the first set:\n", X[0][:4])

# %%
# Fit and predict
# ---------------
# The defaults draw random boxes in the region the training objects span, refine each
# node's best box on its training objects and grow each tree on a bootstrap sample.
forest = BoxExtraTreesRegressor(n_estimators=30, random_state=0)
forest.fit(X_train, y_train)
prediction = forest.predict(X_test)
print(f"R^2 on held-out sets: {forest.score(X_test, y_test):.3f}")

fig, ax = plt.subplots(figsize=(4.5, 4.5))
ax.scatter(y_test, prediction, s=8, alpha=0.5)
ax.axline((0, 0), slope=1, color="grey", lw=1)
ax.set(xlabel="true target", ylabel="predicted", title="Held-out sets")
fig.tight_layout()

# %%
# Which types matter
# ------------------
# :func:`~boxtrees.type_importance` shuffles the objects of one type between the test
# sets and reports the loss of R^2: the enemies (-300 each) matter most, then the coins;
# the distractors do not matter at all.
result = type_importance(forest, X_test, y_test, n_repeats=3, random_state=0)
names = ["coin (0)", "enemy (1)", "distractor (2)", "distractor (3)"]

fig, ax = plt.subplots(figsize=(5, 3))
ax.barh(names, result.importances_mean, xerr=result.importances_std)
ax.invert_yaxis()
ax.set(xlabel="loss of R^2 when the type's objects are shuffled",
       title="type_importance")
fig.tight_layout()

# %%
# Where they matter
# -----------------
# :func:`~boxtrees.region_importance` removes the objects of one type in one cell of a
# grid at a time. The loss concentrates in the cells that overlap the target's square
# (drawn in black), and the forest ignores the rest of the plane.
maps = region_importance(forest, X_test, y_test, n_bins=8, types=[0, 1],
                         extent=10)

fig, axes = plt.subplots(1, 2, figsize=(8, 3.8), sharey=True)
for ax, values, name in zip(axes, maps.importances_mean, names):
    # rows of the image are y, columns x: the map's [x cell, y cell] transposed
    image = ax.imshow(values.T, origin="lower", extent=(-10, 10, -10, 10))
    ax.add_patch(plt.Rectangle((-1.5, -0.5), 3, 3, fill=False, color="black"))
    ax.set(title=name, xlabel="x")
    fig.colorbar(image, ax=ax, shrink=0.8, label="loss of R^2")
axes[0].set_ylabel("y")
fig.tight_layout()

# %%
# The same sets, classified
# -------------------------
# :class:`~boxtrees.BoxExtraTreesClassifier` takes the same input. Here it learns whether
# an enemy is in the square (the target is below -150) and gives a probability per set.
danger = y_train < -150
classifier = BoxExtraTreesClassifier(n_estimators=30, random_state=0)
classifier.fit(X_train, danger)
accuracy = classifier.score(X_test, y_test < -150)
print(f"accuracy on held-out sets: {accuracy:.3f}")

# one enemy at the centre of the square, then the same enemy far away
probe = [np.array([[0.0, 1.0, 1]]), np.array([[8.0, -8.0, 1]])]
proba = classifier.predict_proba(probe)[:, 1]
print("P(enemy in the square):", proba.round(2))
