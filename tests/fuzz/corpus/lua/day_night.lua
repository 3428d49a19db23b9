-- A day-night cycle: the sky (and the sun in it) turns about the vertical,
-- and dims towards night. The sky is updated ten times a second, not every
-- frame: each change rebuilds the light set and wakes the probes.
property("seconds_per_day", 24)
property("turn_per_second", 0.2)
property("night_strength", 0.35)
property("running", true)   -- untick in the inspector to hold the sky still (the reference then converges)

function init(self)
  self.t = 0
  self.since = 1
  self.start_yaw = sky.get_yaw()
  self.day_strength = sky.get_strength()
end

function update(self, dt)
  if not self.running then return end
  self.t = self.t + dt
  self.since = self.since + dt
  if self.since < 0.1 then return end
  self.since = 0
  local phase = 2 * math.pi * self.t / self.seconds_per_day
  local daylight = 0.5 + 0.5 * math.cos(phase)        -- 1 at noon, 0 at midnight
  sky.set_yaw(self.start_yaw + self.turn_per_second * self.t)
  sky.set_strength(self.day_strength * (self.night_strength + (1 - self.night_strength) * daylight))
end
