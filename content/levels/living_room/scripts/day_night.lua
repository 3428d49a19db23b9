-- Time of day: the level's sun (a directional light) follows the hour along
-- a simple arc, rising at 6:00 in the east and setting at 18:00, and the sky
-- dims towards night. `hour` is a property, so the editor's inspector sets
-- the time of day; with `running` ticked the clock advances by itself.
-- The sun is turned ten times a second, not every frame: each turn rebuilds
-- the light set and wakes the probes.
property("hour", 16)               -- 0..24; 16:00 puts the sun where the level was lit from before
property("hours_per_second", 0.05) -- a day in 8 minutes
property("running", true)          -- untick in the inspector to hold the sun still (the reference then converges)
property("noon_elevation", 56.23)  -- degrees above the horizon at 12:00
property("noon_azimuth", 44.06)    -- degrees from +z towards +x at 12:00; the window faces +x
property("night_strength", 0.35)   -- the sky's strength at night, a fraction of the day's

-- Elevation and azimuth (degrees) of the sun at `hour`.
local function sun_at(self, hour)
  local day = (hour - 6) / 12                          -- 0 at sunrise, 1 at sunset
  local elevation = self.noon_elevation * math.sin(math.pi * day)
  local azimuth = self.noon_azimuth + 15 * (hour - 12)  -- 15 degrees an hour
  return elevation, azimuth
end

local function apply(self)
  local elevation, azimuth = sun_at(self, self.hour)
  -- Below the horizon the sun is off and the sky holds the night light;
  -- over the first 5 degrees both fade in.
  local daylight = math.max(0, math.min(1, elevation / 5))
  sun.set(math.max(-89, math.min(89, elevation)), azimuth)
  self.sun_light:set_intensity(self.sun_intensity * daylight)
  sky.set_strength(self.day_strength * (self.night_strength + (1 - self.night_strength) * daylight))
end

function init(self)
  self.sun_light = scene.find("Sun").light
  self.sun_intensity = self.sun_light:get_intensity()
  self.day_strength = sky.get_strength()
  self.since = 1
  self.shown_hour = nil
end

function update(self, dt)
  if self.running then self.hour = (self.hour + self.hours_per_second * dt) % 24 end
  self.since = self.since + dt
  if self.hour == self.shown_hour or self.since < 0.1 then return end
  self.since = 0
  self.shown_hour = self.hour
  apply(self)
end
