-- The door's key: it lies on the table until the player walks within
-- `reach` metres, then tells the door and disappears. (It does not spin:
-- anything that moves re-lights the scene and restarts the reference view.)
property("door", "DoorHinge")
property("reach", 1.2)

function init(self)
  self.camera = scene.find("Camera")
end

function update(self, dt)
  local cx, cy, cz = self.camera.transform:get_world_position()
  local x, y, z = self.entity.transform:get_world_position()
  local d = math.sqrt((cx - x)^2 + (cy - y)^2 + (cz - z)^2)
  if d < self.reach then
    log.info(string.format("picked up the key (%.2f m away)", d))
    send(scene.find(self.door), "got_key", {})
    scene.despawn(self.entity)
  end
end
