"""How noisy the simulated sensors are: :class:`SensorNoise`, plain data.

A world's noise (``world.noise``) is set through its fault settings
(:meth:`~alica.worldsim.faults.Faults.set_sensor_noise`) and read by the
sensors, the robots' cameras and their odometry.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["SensorNoise"]


@dataclass(frozen=True, slots=True)
class SensorNoise:
    """Noise of the simulated sensors.

    Attributes:
        lidar_sigma: standard deviation (m) of the Gaussian noise added to lidar hits.
        position_sigma: standard deviation (m) of a camera detection's position at close range;
            it grows linearly to twice that at the perception range; 3-D perception has a quarter of it.
        camera_misclassification: probability that a camera reports a wrong sample kind.
        stereo_misclassification: the same for 3-D (stereo and 3-D lidar) perception.
        pixel_sigma: standard deviation of the Gaussian noise on each colour channel of a robot
            camera's pixels, in intensity levels (0-255).
        depth_sigma: standard deviation (m) of a robot camera's depth at 1 m; it grows with the
            square of the distance, as a stereo pair's does.
        odometry_drift: relative error of the robots' odometry (0.02 = 2 %): each step's distance and
            turn are scaled by ``1 + drift * (bias + noise)`` (see :mod:`alica.worldsim.odometry`);
            0 keeps every robot's pose estimate equal to its true pose.
    """

    lidar_sigma: float = 0.0
    position_sigma: float = 0.03
    camera_misclassification: float = 0.1
    stereo_misclassification: float = 0.01
    pixel_sigma: float = 2.0
    depth_sigma: float = 0.005
    odometry_drift: float = 0.0
