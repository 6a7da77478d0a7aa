"""rclpy nodes wrapping football_ros.physics: they pace, convert and publish."""
