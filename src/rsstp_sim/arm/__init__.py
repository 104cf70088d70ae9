"""The arm: a body of links turned one joint at a time among circular obstacles.

- :mod:`~rsstp_sim.arm.geometry`: the collision semantics and the feedback, in the plane;
- :mod:`~rsstp_sim.arm.table`: every pose's answers, tabulated (the one home of the world's
  answers);
- :mod:`~rsstp_sim.arm.world`: the arm as a :class:`~rsstp_sim.interface.World`, and as a
  registered body (``ARM``);
- :mod:`~rsstp_sim.arm.picture`: its frames for the Gymnasium env.

Only this package imports the arm's geometry and table (``tests/test_house.py`` checks it).
"""
