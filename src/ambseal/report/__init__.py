"""ambseal.report"""
