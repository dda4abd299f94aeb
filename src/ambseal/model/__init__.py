"""ambseal.model"""
