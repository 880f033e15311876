# rosbag2 SQLite bags (.db3, CDR messages) read without ROS.

test_that("a db3 bag gives the CSV's record", {
  ref <- read_imu(ros_fixture("imu.csv"))
  r <- read_imu(ros_fixture("imu.db3"), topic = "/imu0")
  expect_identical(r$layout, "db3")
  expect_identical(unname(r$data), unname(ref$data))
  expect_identical(r$time, ref$time)
  expect_identical(r$freq, ref$freq)
  expect_identical(r$segments, ref$segments)
  expect_equal(nrow(r$problems), 0L)
})

test_that("db3 topics are listed with their counts; a non-IMU topic is refused", {
  f <- ros_fixture("imu.db3")
  tp <- imu_topics(f)
  expect_identical(tp$topic, c("/imu0", "/imu1", "/temperature"))
  expect_identical(tp$messages, c(300, 20, 5))
  expect_error(read_imu(f, topic = "/temperature"), "std_msgs/msg/Float64",
               class = "allanvar_error_topic")
  expect_equal(nrow(read_imu(f, topic = "/imu1")$data), 20L)
})

test_that("an SQLite file that is not a bag is refused clearly", {
  f <- tempfile(fileext = ".db3")
  on.exit(unlink(f))
  con <- DBI::dbConnect(RSQLite::SQLite(), f)
  DBI::dbExecute(con, "CREATE TABLE t(x INTEGER)")
  DBI::dbDisconnect(con)
  expect_error(read_imu(f), "not a rosbag2", class = "allanvar_error_file_format")
})
